#pragma once
// Trajectory prediction (section V-A: "the corresponding object trajectories are predicted by
// numerically solving (8) and (9) over the timespan of Delta T"): M objects, a horizon, and a
// piecewise-constant schedule of nozzle orientations. One interface, two implementations:
//   CvodePredictor (models/cvode_predictor.h): the reference, CVODE Adams at tight tolerances;
//   FastPredictor  (models/fast_predictor.h):  what the controller uses, fixed-step RK4 per ray.
//
// The model (models/object_dynamics.h): eq. (8) for the speed v, eq. (9) for the direction, radial
// from the current stagnation point s. When the orientation changes, v carries over and the
// direction becomes radial from the new s. A moving object stops when v reaches 0 (an event: v is
// set to exactly 0 at the crossing); a resting object stays put while xi2 v_air + xi3 <= 0 and
// starts moving at the first orientation that makes it positive.
//
// Thread safety: predictors are immutable after construction and predict() is const; each call
// owns its scratch, so one predictor serves any number of threads (each with its own output).

#include <Eigen/Core>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "models/air_field.h"
#include "models/nozzle_geometry.h"
#include "models/object_dynamics.h"

namespace airtwin {

/// A numerical integration failed (e.g. a SUNDIALS error). The message names the solver, the
/// failing call, its return code, the time and the object.
class IntegrationError : public std::runtime_error {
 public:
  explicit IntegrationError(const std::string& message) : std::runtime_error(message) {}
};

/// The state of one object: position on the floor and the speed of eq. (8).
struct ObjectState {
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();  ///< m, world frame
  double v = 0.0;  ///< m/s, >= 0; the object moves radially away from s at this speed
};

/// From t_start_s on (s, until the next change) the nozzle holds `orientation`.
struct OrientationChange {
  double t_start_s = 0.0;
  NozzleOrientation orientation;
};
/// Piecewise-constant orientations: non-empty, t_start strictly increasing, the first <= 0 (so
/// the orientation at t = 0 is defined). Changes at or after the horizon are ignored.
using OrientationSchedule = std::vector<OrientationChange>;

struct PredictionOptions {
  double horizon_s = 1.5;  ///< Delta T of section V-A; finite, > 0
  /// 0: end states only. > 0: also sample every object at t_k = k / rate, k = 0..floor(horizon *
  /// rate) (e.g. 40 for the camera's frames). At most 1e6 samples per object.
  double sample_rate_hz = 0.0;
};

/// The result for M objects. Reused between calls without reallocating when sizes repeat.
struct Prediction {
  size_t n_objects = 0;
  std::vector<ObjectState> end;  ///< state at t = horizon, per object
  /// Per object: the time (s) since which the object has been at rest at the horizon (0 when it
  /// never moved), or +infinity when it is still moving there.
  std::vector<double> rest_since_s;
  std::vector<double> sample_times_s;  ///< t_k; empty without sampling
  std::vector<ObjectState> samples;    ///< sample k of object j at [k * n_objects + j]

  const ObjectState& sample(size_t k, size_t j) const { return samples[k * n_objects + j]; }
  bool at_rest(size_t j) const { return rest_since_s[j] < std::numeric_limits<double>::infinity(); }
};

/// Predicts object trajectories under eqs. (8)-(9). Implementations differ only in how they
/// integrate one schedule segment; validation, segmentation and sampling are shared here.
class TrajectoryPredictor {
 public:
  virtual ~TrajectoryPredictor() = default;
  virtual std::string name() const = 0;

  /// Predicts objects j = 0..M-1 (dynamics[j], start[j] at t = 0) under `schedule`, fields from
  /// `model`. Throws InputError when sizes differ, a state is not finite or has v < 0, the
  /// coefficients are not finite, the schedule or options are invalid, or a tilt is outside
  /// [0, 90) deg; IntegrationError when the solver fails.
  void predict(const AirFieldModel& model, const OrientationSchedule& schedule,
               std::span<const ObjectDynamics> dynamics, std::span<const ObjectState> start,
               const PredictionOptions& options, Prediction& out) const;
  /// One orientation for the whole horizon, its field already built (the controller's case:
  /// one OrientedField per candidate). Same errors.
  void predict(const OrientedField& field, std::span<const ObjectDynamics> dynamics,
               std::span<const ObjectState> start, const PredictionOptions& options,
               Prediction& out) const;
  /// The same with the field seen along rays (AirFieldModel::rays_at: cheaper to build when the
  /// predictor follows rays, as FastPredictor does). Same errors.
  void predict(const OrientedRays& rays, std::span<const ObjectDynamics> dynamics,
               std::span<const ObjectState> start, const PredictionOptions& options,
               Prediction& out) const;

  /// Conveniences returning a fresh Prediction.
  Prediction predict(const AirFieldModel& model, const OrientationSchedule& schedule,
                     std::span<const ObjectDynamics> dynamics, std::span<const ObjectState> start,
                     const PredictionOptions& options = {}) const;
  Prediction predict(const OrientedField& field, std::span<const ObjectDynamics> dynamics,
                     std::span<const ObjectState> start,
                     const PredictionOptions& options = {}) const;
  Prediction predict(const OrientedRays& rays, std::span<const ObjectDynamics> dynamics,
                     std::span<const ObjectState> start,
                     const PredictionOptions& options = {}) const;

 protected:
  /// One segment of constant orientation, [t0_s, t1_s]. Its field comes in one of two views,
  /// exactly one set: the full field when the caller built one, else the rays (the schedule
  /// path builds only those; OrientedRays::field() gives the full one).
  struct Segment {
    const OrientedField* field = nullptr;
    const OrientedRays* rays = nullptr;
    double t0_s = 0.0;
    double t1_s = 0.0;
    /// Sample times inside (t0, t1], increasing; the states there go to
    /// samples[i * n_objects + j] for sample_times[i].
    std::span<const double> sample_times_s;
    ObjectState* samples = nullptr;
  };

  /// Advances every object over `segment`: state[j] holds the state at t0 on entry and at t1 on
  /// return. rest_since_s[j] follows the convention of Prediction (on entry +infinity when the
  /// object has not been at rest so far): an object at rest at t0 keeps its value (or gets t0);
  /// one moving at t0 gets +infinity, then the stop time if it stops. Inputs are validated.
  virtual void advance(const Segment& segment, std::span<const ObjectDynamics> dynamics,
                       std::span<ObjectState> state, std::span<double> rest_since_s) const = 0;

 private:
  // The segments' fields come from `fields` or, when it is empty, from `rays`.
  void run(std::span<const OrientedField> fields, std::span<const OrientedRays> rays,
           std::span<const double> starts_s, std::span<const ObjectDynamics> dynamics,
           std::span<const ObjectState> start, const PredictionOptions& options,
           Prediction& out) const;
};

}  // namespace airtwin
