#pragma once
// The discrepancy analysis's fits (models/discrepancy.h, step 2): each candidate effect's
// parameters in coordinates where the cost is smooth, the grid each fit starts from, the
// ordinary static friction every fit carries as a nuisance, and Levenberg-Marquardt on top.
// Internal to the analysis.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "models/discrepancy_evaluation.h"
#include "models/model_extensions.h"

namespace airtwin::discrepancy_detail {

// Each extension is fitted in coordinates where the cost is smooth: its typed parameters, except
// floor_slope, fitted as the downhill pull's components (angle_deg cos dir, angle_deg sin dir) so
// that a level floor is not a singular point of the direction.

struct FitBox {
  std::vector<double> lo, hi;
};

FitBox fit_box(const std::string& name);
// The number of parameters a cause is fitted with (its box's dimension).
int parameter_count(const std::string& name);
// Typed values from fit coordinates, and back.
std::vector<double> typed_from_fit(const std::string& name, const double* x);
std::vector<double> fit_from_typed(const std::string& name, const std::vector<double>& v);

// The grid each fit starts from: per fit coordinate, its starting values.
std::vector<std::vector<double>> fit_grid(const std::string& name);

// The extensions `names` set from the concatenated fit coordinates x, on top of `base`.
ModelExtensions apply_fit(const ModelExtensions& base, const std::vector<std::string>& names,
                          const double* x);

// Levenberg-Marquardt over the training windows' residuals in the fit coordinates of `names`
// on top of `base`, from *x (refined in place), at most max_iterations evaluations. Returns the
// evaluations spent.
int refine_fit(const Evaluator& ev, const std::vector<size_t>& train, const ModelExtensions& base,
               const std::vector<std::string>& names, int max_iterations, Eigen::VectorXd* x,
               Fidelity fidelity = Fidelity::kFull);

// A fit near a known answer (the bootstrap's refits): from *x, a compass search over every
// coordinate of `names` with steps from 1/2 down to 1/16 of each coordinate's grid pitch (as the
// fits' own compass: on a stepwise cost smaller first steps stay on the answer's plateau), then
// Levenberg-Marquardt (at most max_iterations evaluations; 0: none), every prediction at
// `fidelity`. Returns the evaluations spent.
int polish_fit(const Evaluator& ev, const std::vector<size_t>& train, const ModelExtensions& base,
               const std::vector<std::string>& names, int max_iterations, Fidelity fidelity,
               std::vector<double>* x);

// Per fit coordinate of `names` (concatenated), the compass's finest step: a sixteenth of the
// coordinate's grid pitch, the resolution of every fit and refit.
std::vector<double> fit_finest_steps(const std::vector<std::string>& names);

// The ordinary static friction, a nuisance of every fit.
// Every dry contact holds somewhat above its kinetic friction (static / kinetic 1-1.3), which
// eq. (8)'s start condition (xi2 v_air + xi3 > 0) ignores. Which objects start carries much of the
// information about a slope (the pull's direction moves the threshold), a push or a nozzle offset
// (the distance from s does), so a fit without it bends their parameters to make the starts
// agree (measured: docs/decisions.md, 2026-11-23). So every fit carries the ratio as a nuisance:
// fitted on a grid within the ordinary range, reported, but not a cause and not part of the
// extended model. The stiction candidate (a ratio above that range) replaces it.
constexpr double kOrdinaryStictionStep = 0.025;
constexpr int kOrdinaryStictionGrid = 13;  // 1, 1.025, ..., 1.3 (stiction's negligible size)

double fit_ordinary_stiction(const Evaluator& ev, const std::vector<size_t>& train,
                             const ModelExtensions& base);

struct FitResult {
  ModelExtensions ext;
  double sse = INFINITY;
  int evaluations = 0;         ///< at the full step
  int screen_evaluations = 0;  ///< at the screening step (the grid)
};

// Fits `names` (their fit coordinates concatenated) on top of `base`: the grid over the last
// name's coordinates (the earlier ones start from `x0`), then Levenberg-Marquardt over all. With
// `fit_nuisance`, the grid runs at the base's ratio and at kinetic = static friction (a ratio
// fitted to the nominal model can absorb part of a large effect and trap the grid: a 9 deg pan
// offset's missed starts read as 1.28 and the offset was then missed; the grid at 1 alone missed a
// slope in data made with 1.2), the ordinary static friction is fitted under the better grid
// point, and Levenberg-Marquardt refines on top of it.
FitResult fit_extensions(const Evaluator& ev, const std::vector<size_t>& train,
                         const ModelExtensions& base, const std::vector<std::string>& names,
                         std::vector<double> x0, int max_iterations, bool fit_nuisance);

}  // namespace airtwin::discrepancy_detail
