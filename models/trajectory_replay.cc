#include "models/trajectory_replay.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>

#include "common/errors.h"
#include "common/units.h"
#include "models/nozzle_geometry.h"

namespace airtwin {

StartFit fit_start(const std::vector<TrajectorySample>& s, size_t first) {
  AIRTWIN_DEMAND(first + 3 <= s.size());
  // Least-squares quadratic p(tau) = a + b tau + c tau^2 through the first frames (tau = t - t0).
  const size_t k = std::min<size_t>(s.size() - first, kStartFrames);
  Eigen::MatrixXd A(k, 3);
  Eigen::MatrixXd P(k, 2);
  for (size_t i = 0; i < k; ++i) {
    const double tau = s[first + i].t_s - s[first].t_s;
    A.row(i) << 1.0, tau, tau * tau;
    P.row(i) = s[first + i].p_W.transpose();
  }
  const Eigen::MatrixXd coef = A.colPivHouseholderQr().solve(P);
  StartFit fit;
  fit.p_W = coef.row(0).transpose();
  fit.v_W = coef.row(1).transpose();
  return fit;
}

ObjectState start_state(const std::vector<TrajectorySample>& s) {
  const StartFit fit = fit_start(s);
  ObjectState start;
  start.p_W = fit.p_W;
  start.v = fit.v_W.norm();
  return start;
}

PlacementSector placement_sector(double bearing_deg) {
  for (const PlacementSectorInfo& info : kPlacementSectorCatalogue) {
    if (bearing_deg < info.max_bearing_deg) return info.sector;
  }
  return PlacementSector::kUpstream;
}

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
    out.tilt_deg = tilt_group_deg(s.front().nozzle.tilt_rad);
    out.measured_end_W = s.back().p_W;
    out.start_W = start_state(s).p_W;
    out.travel_m = (s.back().p_W - out.start_W).norm();

    OrientationSchedule schedule{{0.0, s.front().nozzle}};
    for (size_t k = 1; k < s.size(); ++k) {
      const NozzleOrientation& a = s[k - 1].nozzle;
      const NozzleOrientation& b = s[k].nozzle;
      if (a.pan_rad != b.pan_rad || a.tilt_rad != b.tilt_rad) {
        schedule.push_back({s[k].t_s - t0, b});
      }
    }
    out.constant_command = schedule.size() == 1;

    const ObjectState start = start_state(s);
    PredictionOptions po;
    po.horizon_s = s.back().t_s - t0;
    predictor.predict(field, schedule, std::span(&dynamics, 1), std::span(&start, 1), po,
                      prediction);
    out.predicted_end_W = prediction.end[0].p_W;
    out.error_m = (out.predicted_end_W - out.measured_end_W).norm();
    const NozzleOrientation& first = s.front().nozzle;
    const Eigen::Vector2d from_s = out.start_W - stagnation_point(field.geometry(), first);
    if (from_s.norm() >= kOnStagnationPoint_m) {
      const Eigen::Vector2d pan(std::cos(first.pan_rad), std::sin(first.pan_rad));
      out.bearing_deg = rad_to_deg(
          std::atan2(std::abs(pan.x() * from_s.y() - pan.y() * from_s.x()), pan.dot(from_s)));
    }
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
      const PlacementSector sector = placement_sector(out.bearing_deg);
      SectorFigures& f = report.by_tilt_sector[out.tilt_deg][static_cast<size_t>(sector)];
      ++f.n;
      f.mape_pct += out.error_pct;  // a sum until the end
      if ((out.predicted_end_W - out.start_W).norm() < options.min_travel_m) ++f.n_predicted_rest;
    }
    report.trajectories.push_back(out);
  }
  report.mape_pct =
      report.n_used ? sum_pct / report.n_used : std::numeric_limits<double>::quiet_NaN();
  for (const auto& [tilt, acc] : by_tilt) report.mape_by_tilt_pct[tilt] = acc.first / acc.second;
  for (auto& [tilt, sectors] : report.by_tilt_sector) {
    for (SectorFigures& f : sectors) {
      f.mape_pct =
          f.n ? f.mape_pct / static_cast<double>(f.n) : std::numeric_limits<double>::quiet_NaN();
    }
  }
  return report;
}

}  // namespace airtwin
