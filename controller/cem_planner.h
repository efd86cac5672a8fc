#pragma once
// The model-based controller of section V-A: the cross-entropy method (CEM) over the stagnation
// point s. Candidates s are drawn from a Gaussian, each is turned into the nozzle orientation of
// eqs. (1)-(2), the objects' trajectories over Delta T are predicted with eqs. (8)-(9) (the fast
// predictor), and scored by eq. (10):
//   J = J_P                          if some object starts within delta_min of s,
//   J = sum_j || p_j^end - r_j ||    otherwise.
// The n* cheapest candidates refit the Gaussian; the loop stops when the variance falls below
// Sigma* (the Frobenius norm of the covariance for the bivariate search) or after i_max
// iterations, and returns the final mean.
//
// Two searches, as in the paper:
//  - line (path following, aggregation; sections V-B, V-C): s on the ray from the anchor object
//    (the only one, or the one farthest from its reference) directly away from its reference;
//    a univariate Gaussian over the distance from the anchor, mu0 41.8 cm, Sigma0 20.9 cm^2,
//    n 25, n* 3, i_max 5, Sigma* 0.3 cm^2.
//  - plane (sorting, section V-C): s anywhere; a bivariate Gaussian, mu0 the mean of the objects'
//    positions, Sigma0 diag(31.3, 31.3) cm^2, n 100, n* 10, i_max 5, ||Sigma||_F* 0.5 cm^2.
// SI inside: the paper's cm and cm^2 become m and m^2 (20.9 cm^2 = 20.9e-4 m^2).
//
// Candidates the nozzle cannot produce (beyond the tilt range) cost J_P, like those too close to
// an object. Deterministic: the samples come from a RandomStream the caller seeds.
//
// Two additions the paper does not use, both off unless asked for (sorting in stages uses them,
// controller/task.h; the path files use the scan):
//  - per-object weights and reaches in eq. (10):
//      J = sum_j w_j || p_j^end - r_j || + kOutOfReachCost sum_j max(0, |p_j^end| - R_j),
//    |p| measured from the point below the nozzle; w_j = 1 and R_j = infinity give eq. (10).
//  - a scan before the plane search (scan_step_m > 0): eq. (10) on every point of a square grid
//    of that pitch over the disc of reachable stagnation points; the cheapest feasible point
//    becomes mu0 instead of the objects' mean, and the decision is the cheaper of the search's
//    final mean and that point. With objects spread over the floor the best push can be a metre
//    from their mean, where a Gaussian of a few cm never samples. Every point, not coarse to
//    fine: the pushes that move an object without flinging it are few and near it, and a coarse
//    grid's cheapest points are only its first (docs/controller.md). In the line search the same
//    scan runs only when the search was blind: every feasible sample's cost within 1 mm of the
//    others, i.e. the model moves nothing from anywhere on the ray (an object out where only the
//    weak air upstream of an oblique jet's s would push it toward its reference). The elites are
//    then the first draws and the mean a random walk. The scan finds a push from another side,
//    and the decision is the cheaper of the two. Such a rescue may not spread a group: a point
//    whose predicted ends lie farther apart (largest pairwise distance) than the objects do now
//    is passed over. Eq. (10) has no term for a group's cohesion, and the cheapest rescue often
//    scattered the octagon's four tracers (docs/controller.md).
//
// Cheapest seen (keep_cheapest, not in the paper): s* is the final mean (section V-A), which
// the search never evaluated. When it stops unconverged with the elites on two sides of a ridge
// of penalties (most samples within delta_min of an object or sweeping past one), that mean can
// be a push far worse than any sample it drew: measured in the octagon, a mean 4 cm from the
// point below the nozzle, at tilt 2.6 deg, that flung the four tracers 45 cm out (eq. 10 of
// 1.77 m where the cheapest sample had 0.30 m) to where no stagnation point within the tilt
// range could push them back (docs/controller.md, "The cheapest candidate"). With the option
// the decision is the cheaper of the final mean and the cheapest candidate evaluated.
//
// Transition (predict_transition, not in the paper): eq. (10) is evaluated on the prediction of
// the whole re-aim. The servos take up to ~1 s to turn (7 rad/s, 30 rad/s^2) and never wrap in
// pan, so from pan 140 deg to -95 deg the jet sweeps 235 deg over the floor, and the air follows
// 0.2 s late (models/nozzle_response.h). The paper's prediction applies the new s at once and
// cannot see a sweep that blows an object the other way; here the prediction runs under the
// previous orientation for the transit (once per decision: every candidate shares it), then
// through the servos' sweep (their closed-form moves, ServoMove, in 100 ms pieces each holding
// the orientation at its middle), then Delta T under the new one, all with the fast predictor.
//
// Sweep clearance (sweep_clearance_m, not in the paper): eq. (10)'s penalty J_P keeps s itself
// delta_min from every object, because motion next to s is the most stochastic. A re-aim moves s
// there too: the servos turn for up to ~1 s (never wrapping in pan: from pan -136 deg to 110 deg
// the jet sweeps 246 deg over the floor), and an s that passes a group at a few cm scatters it,
// a push the prediction does not see (a tracer in the passing jet slides 0.1-1 m in the twin, a
// few cm in eq. 8). With a clearance the penalty also covers the path of s while the servos turn
// from the command in force to the candidate's (their closed-form moves, ServoMove, in 10 ms pieces
// taken as straight segments), at the objects' positions at the decision. The servos are
// `transition`'s, or the extended model's. When it leaves no candidate (the pan must sweep past the
// objects to reach any push: the servos never wrap), the decision is the paper's, the search run
// again without it (PlanResult::sweep_blocked). Measured in the twin (docs/controller.md, "The
// re-aim's sweep"): within delta_min of a passing s, half the objects end more than 10 cm from
// their prediction.
//
// Extended planning (an extended model from `airtwin discrepancy`, models/extended_model.h): the
// trajectories are predicted with models/extended_predictor.h instead, under the model's
// extensions and the nozzle's response. The new command takes over from the previous one through
// the servos and the field's delay (models/nozzle_response.h), the objects start from their full
// observed velocity, and the prediction runs until the new field has acted for Delta T (to
// Delta T plus the transit, any response_delay and the transport lag to the farthest object).
// A nozzle_offset is compensated: the command
// is the aim of eqs. (1)-(2) minus the offset (tilt no lower than 0), and the prediction sees
// where the air then goes.

#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "common/random_stream.h"
#include "models/air_field.h"
#include "models/extended_predictor.h"
#include "models/fast_predictor.h"
#include "models/model_extensions.h"
#include "models/nozzle_geometry.h"
#include "models/nozzle_response.h"
#include "models/object_dynamics.h"
#include "models/trajectory_predictor.h"

namespace airtwin {

enum class CemSearch { kLine, kPlane };

/// Cost per metre an object ends beyond its reach R_j (cost units are metres of distance): a
/// wall soft enough to leave the search a gradient, steep enough that no distance gain pays for
/// crossing it.
inline constexpr double kOutOfReachCost = 10.0;

struct CemParameters {
  CemSearch search = CemSearch::kLine;
  double horizon_s = 1.5;        ///< Delta T (s)
  double penalty = 1e3;          ///< J_P (cost units: m, like the distances it competes with)
  double min_distance_m = 0.10;  ///< delta_min (m)
  /// Line: initial mean distance of s from the anchor (m). Plane: unused (mean of positions).
  double mean0_m = 0.418;
  /// Initial variance (m^2): of the distance (line), of each axis (plane).
  double variance0_m2 = 20.9e-4;
  int samples = 25;        ///< n
  int elite = 3;           ///< n*
  int max_iterations = 5;  ///< i_max
  /// Sigma* (m^2): the variance (line) or the covariance's Frobenius norm (plane) below which
  /// the search has converged.
  double converged_variance_m2 = 0.3e-4;
  /// Pitch (m) of the grid scan (see above); 0, the paper's choice: no scan. Plane search: the
  /// scan sets mu0. Line search: the disc is scanned only when the search was blind, for a push
  /// that does not spread the objects.
  double scan_step_m = 0.0;
  /// Predict the re-aim too (see above): the air keeps the previous orientation for the
  /// transit, then sweeps with the servos to the new one. false: the paper's model, the new
  /// field at once. Needs the previous command (PlanningProblem::nozzle_now).
  bool predict_transition = false;
  /// The servos and the transit that the transition follows (the rig's specification).
  NozzleResponseParameters transition;
  /// J_P also for a re-aim whose stagnation point passes within this distance (m) of an object
  /// while the servos turn (see above). 0, the paper's: the penalty on the new s only. Needs the
  /// previous command (PlanningProblem::nozzle_now); without it only the new s is checked.
  double sweep_clearance_m = 0.0;
  /// The decision is the cheaper of the final mean and the cheapest candidate the search
  /// evaluated (see above). false, the paper's: the final mean, whatever it costs.
  bool keep_cheapest = false;

  /// The paper's values for each search.
  static CemParameters line_defaults();
  static CemParameters plane_defaults();

  /// Throws InputError naming `source` and the field when a value is not finite or out of range
  /// (elite must be in [1, samples]).
  void validate(const std::string& source) const;
};

/// Planning with an extended model instead of eqs. (8)-(9) (see the top of this file).
struct ExtendedPlanning {
  ModelExtensions extensions;         ///< what the model adds (SI)
  NozzleResponseParameters response;  ///< the servos and the transit the model assumes
  double step_s = 2e-3;               ///< the extended predictor's step (s)
};

/// One decision's inputs.
struct PlanningProblem {
  std::span<const Eigen::Vector2d> positions_W;  ///< p_j^init (m)
  /// Each object's current speed (m/s, >= 0) along its radial direction from the candidate s is
  /// taken as max(0, v_W . e_r): what carries over under eq. (9) when the orientation changes.
  std::span<const Eigen::Vector2d> velocities_W;
  std::span<const ObjectDynamics> dynamics;  ///< eq. (8) coefficients per object
  /// Each object's type: extended planning with effects per type gives each object its type's
  /// (ModelExtensions::object_for); may be empty otherwise.
  std::span<const std::string> types;
  std::span<const Eigen::Vector2d> references_W;  ///< r_j (m)
  /// w_j, each finite and >= 0; empty: all 1 (eq. 10).
  std::span<const double> weights;
  /// R_j (m): how far from the point below the nozzle object j should end, > 0 or +infinity;
  /// empty: no limit.
  std::span<const double> reach_m;
  /// Line search only: the anchor object (farthest from its reference when < 0).
  int anchor = -1;
  /// Current nozzle pan (rad): the pan used for s at the origin.
  double pan_hint_rad = 0.0;
  /// Extended planning only: the command the nozzle rests at now (the previous decision's);
  /// unset, the nozzle is taken to be at the new command already.
  std::optional<NozzleOrientation> nozzle_now;
};

struct PlanResult {
  Eigen::Vector2d stagnation_W = Eigen::Vector2d::Zero();  ///< s* (m)
  NozzleOrientation orientation;  ///< its nozzle orientation (eqs. 1-2 inverted)
  double cost = 0.0;              ///< eq. (10) at s*
  int iterations = 0;
  int evaluations = 0;      ///< candidates predicted (J_P ones not counted)
  bool converged = false;   ///< Sigma fell below Sigma*
  bool blind_scan = false;  ///< line search: no sample moved anything, the disc was scanned
  /// Sweep clearance blocked every candidate; the decision is the paper's (see above).
  bool sweep_blocked = false;
  /// Predicted end positions at s* (m), per object.
  std::vector<Eigen::Vector2d> predicted_end_W;
};

class CemPlanner {
 public:
  /// `model` must outlive the planner. With `extended`, trajectories are predicted with the
  /// extended model (see above). Throws InputError for invalid parameters.
  CemPlanner(const AirFieldModel& model, const CemParameters& params,
             const FastPredictor::Options& predictor_options = {},
             std::optional<ExtendedPlanning> extended = std::nullopt);

  /// One decision. Throws InputError when sizes differ, nothing is to be planned (no objects) or
  /// a value is not finite. When no candidate is feasible the result has cost J_P and the
  /// orientation is the last mean's nearest reachable one.
  PlanResult plan(const PlanningProblem& problem, RandomStream& rng) const;

  /// eq. (10) for one candidate s (J_P when infeasible); `end_W` receives the predicted ends.
  double cost(const PlanningProblem& problem, const Eigen::Vector2d& s_W,
              std::vector<Eigen::Vector2d>* end_W = nullptr) const;

  /// eq. (10) for s on the positions the objects reached (m), not predicted ones: J_P when an
  /// object started within delta_min of s or the nozzle cannot put s there, else the weighted
  /// distances to the references (and the reach terms). Throws InputError when sizes differ.
  double outcome_cost(const PlanningProblem& problem, const Eigen::Vector2d& s_W,
                      std::span<const Eigen::Vector2d> end_W) const;

  const CemParameters& parameters() const { return params_; }
  const std::optional<ExtendedPlanning>& extended() const { return extended_; }

  /// Threads that predict a decision's candidates (1 by default: the calling thread alone). Any
  /// number gives the same decision, bit for bit: the samples are drawn before they are
  /// predicted, and the results are taken in the candidates' order. Throws InputError unless
  /// `threads` is in [1, kMaxThreads].
  void set_threads(int threads);
  static constexpr int kMaxThreads = 256;
  int threads() const { return threads_; }

 private:
  PlanResult plan_with(const CemParameters& p, const PlanningProblem& problem,
                       RandomStream& rng) const;

  const AirFieldModel& model_;
  CemParameters params_;
  FastPredictor predictor_;
  std::optional<ExtendedPlanning> extended_;
  std::optional<ExtendedPredictor> extended_predictor_;
  int threads_ = 1;
};

}  // namespace airtwin
