#include "models/trajectory_replay.h"

#include <cmath>
#include <limits>

#include "common/units.h"

namespace airtwin {

ReplayReport replay_trajectories(const TrajectorySet& set, const AirFieldModel& field,
                                 const ObjectDynamics& dynamics,
                                 const TrajectoryPredictor& predictor,
                                 const ReplayOptions& options) {
  ReplayReport report;
  std::map<double, std::pair<double, size_t>> by_tilt;  // sum of percentages, count
  double sum_pct = 0.0;
  Prediction prediction;
  for (const Trajectory& tr : set.trajectories) {
    ReplayedTrajectory out;
    out.id = tr.id;
    const std::vector<TrajectorySample>& s = tr.samples;
    if (s.size() < 3) {
      ++report.n_excluded;
      report.trajectories.push_back(out);
      continue;
    }
    const double t0 = s.front().t_s;
    out.tilt_deg = std::round(rad_to_deg(s.front().nozzle.tilt_rad) * 1e3) / 1e3;
    out.measured_end_W = s.back().p_W;
    out.travel_m = (s.back().p_W - s.front().p_W).norm();

    OrientationSchedule schedule{{0.0, s.front().nozzle}};
    for (size_t k = 1; k < s.size(); ++k) {
      const NozzleOrientation& a = s[k - 1].nozzle;
      const NozzleOrientation& b = s[k].nozzle;
      if (a.pan_rad != b.pan_rad || a.tilt_rad != b.tilt_rad) {
        schedule.push_back({s[k].t_s - t0, b});
      }
    }
    out.constant_command = schedule.size() == 1;

    const double dt = s[1].t_s - s[0].t_s;
    ObjectState start;
    start.p_W = s[0].p_W;
    start.v = (-3.0 * s[0].p_W + 4.0 * s[1].p_W - s[2].p_W).norm() / (2.0 * dt);
    PredictionOptions po;
    po.horizon_s = s.back().t_s - t0;
    predictor.predict(field, schedule, std::span(&dynamics, 1), std::span(&start, 1), po,
                      prediction);
    out.predicted_end_W = prediction.end[0].p_W;
    out.error_m = (out.predicted_end_W - out.measured_end_W).norm();
    if (out.travel_m < options.min_travel_m) {
      ++report.n_excluded;
      report.trajectories.push_back(out);
      continue;
    }
    out.used = true;
    out.error_pct = 100.0 * out.error_m / out.travel_m;
    ++report.n_used;
    sum_pct += out.error_pct;
    if (out.constant_command) {
      auto& [sum, count] = by_tilt[out.tilt_deg];
      sum += out.error_pct;
      ++count;
    }
    report.trajectories.push_back(out);
  }
  report.mape_pct =
      report.n_used ? sum_pct / report.n_used : std::numeric_limits<double>::quiet_NaN();
  for (const auto& [tilt, acc] : by_tilt) report.mape_by_tilt_pct[tilt] = acc.first / acc.second;
  return report;
}

}  // namespace airtwin
