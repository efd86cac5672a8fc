#pragma once
// Appendix D trials with a lead-in for the discrepancy analysis's tests, as `airtwin collect
// --lead-in 0.5` records them: 0.5 s at the idle command (pan -90, tilt 50 deg), the re-aim at
// t = 0 to a random pan at tilt 0 or 22.5 deg, 2 s at 40 Hz; the object starts at rest 20-58 cm
// from the trial's s. The plant (what moves the object) is the test's.

#include <Eigen/Core>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "common/units.h"
#include "models/air_field.h"
#include "models/extended_predictor.h"
#include "models/nozzle_response.h"
#include "models/trajectory_data.h"

namespace airtwin::testing {

// Positions at `times` of an object starting at `start` under `timeline`.
using Plant =
    std::function<void(const NozzleTimeline& timeline, const WindowStart& start,
                       const std::vector<double>& times, std::vector<Eigen::Vector2d>* positions)>;

inline TrajectorySet appendix_d_trials(const AirFieldModel& field, int trials, std::uint64_t seed,
                                       const Plant& plant) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const NozzleOrientation idle{deg_to_rad(-90.0), deg_to_rad(50.0)};
  TrajectorySet set;
  for (int i = 0; i < trials; ++i) {
    const NozzleOrientation target{deg_to_rad(360.0 * unit(rng) - 180.0),
                                   deg_to_rad(i % 2 == 0 ? 0.0 : 22.5)};
    const Eigen::Vector2d s = field.at(target).stagnation_point();
    const double r = 0.20 + 0.38 * unit(rng), a = 2.0 * kPi * unit(rng);
    WindowStart start;
    start.t_s = -0.5;
    start.p_W = s + r * Eigen::Vector2d(std::cos(a), std::sin(a));
    const NozzleTimeline timeline(NozzleResponseParameters{}, {{-0.5, idle}, {0.0, target}}, 2.0);
    std::vector<double> times;
    for (int k = -20; k <= 80; ++k) times.push_back(k / 40.0);
    std::vector<Eigen::Vector2d> p;
    plant(timeline, start, times, &p);
    Trajectory tr;
    tr.id = std::to_string(i);
    tr.object = "tracer";
    for (size_t k = 0; k < times.size(); ++k) {
      tr.samples.push_back({times[k], p[k], times[k] < 0.0 ? idle : target});
    }
    set.trajectories.push_back(std::move(tr));
  }
  return set;
}

// The extended model itself as the plant, with `truth`'s extensions.
inline Plant extended_model_plant(const AirFieldModel& field, const ModelExtensions& truth,
                                  const ObjectDynamics& xi) {
  return [&field, truth, xi](const NozzleTimeline& timeline, const WindowStart& start,
                             const std::vector<double>& times,
                             std::vector<Eigen::Vector2d>* positions) {
    const ExtendedPredictor plant(field);
    plant.predict(xi, truth, timeline, start, times, positions);
  };
}

}  // namespace airtwin::testing
