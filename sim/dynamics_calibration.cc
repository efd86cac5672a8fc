#include "sim/dynamics_calibration.h"

#include <algorithm>
#include <cmath>

#include "common/errors.h"
#include "common/random_stream.h"
#include "common/units.h"

namespace airtwin {

void set_physics(const ObjectDynamics& x, ObjectTypeParameters* p, double g) {
  const ObjectTypeParameters q =
      ObjectTypeParameters::from_dynamics(x, p->diameter_m, p->mass_kg, g);
  p->drag_rate_per_s = q.drag_rate_per_s;
  p->air_gain = q.air_gain;
  p->kinetic_friction = q.kinetic_friction;
}

DynamicsCalibration calibrate_dynamics(
    const DynamicsCalibrationOptions& o, const AirFieldModel& field,
    const std::function<void(const DynamicsCalibrationStep&, int, int)>& progress) {
  o.target.validate("calibration target");
  if (o.iterations < 1) throw FieldError("calibration.iterations", "expected at least 1");
  CollectionOptions collection = o.collection;
  ObjectTypeParameters& type =
      collection.object == "tracer" ? collection.twin.scene.tracer : collection.twin.scene.cotton;
  ObjectDynamics x = type.dynamics();

  DynamicsCalibration result;
  double best = INFINITY;
  for (int round = 0; round < o.iterations; ++round) {
    set_physics(x, &type);
    const TrajectorySet data = run_collection(collection, field);
    const IdentifiedModel m =
        identify_trajectories(data, collection.object, field, o.identification);
    std::string problem;
    if (!m.is_eq8()) problem = m.eq8_note();
    DynamicsCalibrationStep step;
    step.physics = x;
    double e1 = 0, e2 = 0, e3 = 0;
    if (problem.empty()) {
      step.identified = m.eq8();
      step.r2 = m.r2;
      step.end_position_mape_pct = m.end_position_mape_pct.value_or(NAN);
      step.mape_by_tilt_pct = m.end_position_mape_by_tilt_pct;
      e1 = step.identified.xi1 / o.target.xi1;
      e2 = step.identified.xi2 / o.target.xi2;
      e3 = step.identified.xi3 / o.target.xi3;
      if (!(e1 > 0 && e2 > 0 && e3 > 0)) problem = "an identified coefficient has the wrong sign";
    }
    if (!problem.empty()) {
      const std::string where = "calibration round " + std::to_string(round + 1) + " (physics " +
                                std::to_string(x.xi1) + ", " + std::to_string(x.xi2) + ", " +
                                std::to_string(x.xi3) + "): " + problem;
      if (result.history.empty()) throw InputError(where);
      result.stopped = where;
      break;
    }
    step.worst_relative_error = std::max({std::abs(e1 - 1), std::abs(e2 - 1), std::abs(e3 - 1)});
    result.history.push_back(step);
    if (step.worst_relative_error < best) {
      best = step.worst_relative_error;
      result.physics = x;
    }
    x = {x.xi1 / e1, x.xi2 / e2, x.xi3 / e3};
    if (progress) progress(step, round + 1, o.iterations);
  }
  return result;
}

std::optional<double> repeatability_mape_pct(const CollectionTrial& trial,
                                             const CollectionOptions& options,
                                             const AirFieldModel& field, int repeats,
                                             double placement_m) {
  if (repeats < 2) throw FieldError("repeatability.repeats", "at least 2 repeats are needed");
  Eigen::Vector2d first_end = Eigen::Vector2d::Zero();
  double travel = 0.0, sum = 0.0;
  for (int i = 0; i < repeats; ++i) {
    CollectionTrial t = trial;
    RandomStream rs(trial.twin_seed, RandomPurpose::kCollection, static_cast<uint64_t>(i));
    t.twin_seed = static_cast<uint64_t>(rs.uniform() * 0x1.0p53);
    // Placed by hand again: uniform in a disc of radius placement_m around the start.
    const double a = rs.uniform(-kPi, kPi), r = placement_m * std::sqrt(rs.uniform());
    if (i > 0) t.start_W += r * Eigen::Vector2d(std::cos(a), std::sin(a));
    const Trajectory tr = run_collection_trial(t, options, field);
    const Eigen::Vector2d end = tr.samples.back().p_W;
    if (i == 0) {
      first_end = end;
      travel = (end - tr.samples.front().p_W).norm();
      if (travel < 0.01) return std::nullopt;
    } else {
      sum += 100.0 * (end - first_end).norm() / travel;
    }
  }
  return sum / (repeats - 1);
}

}  // namespace airtwin
