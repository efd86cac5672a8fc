#include "models/discrepancy_residuals.h"

#include <cmath>

#include "common/units.h"

namespace airtwin::discrepancy_detail {
namespace {

std::vector<ResidualBin> bin_residuals(const std::vector<ResidualSample>& samples,
                                       const std::vector<double>& edges,
                                       double (*value)(const ResidualSample&)) {
  std::vector<ResidualBin> bins;
  for (size_t b = 0; b + 1 < edges.size(); ++b) bins.push_back({edges[b], edges[b + 1]});
  for (const ResidualSample& s : samples) {
    const double v = value(s);
    for (ResidualBin& b : bins) {
      if (v >= b.lo && v < b.hi) {
        ++b.n;
        b.radial_cm += 100.0 * s.radial_m;
        b.tangential_cm += 100.0 * s.tangential_m;
        b.norm_cm += 100.0 * std::hypot(s.radial_m, s.tangential_m);
        break;
      }
    }
  }
  for (ResidualBin& b : bins) {
    if (b.n > 0) {
      b.radial_cm /= static_cast<double>(b.n);
      b.tangential_cm /= static_cast<double>(b.n);
      b.norm_cm /= static_cast<double>(b.n);
    }
  }
  return bins;
}

std::vector<double> edges(double lo, double hi, int n) {
  std::vector<double> e;
  for (int i = 0; i <= n; ++i) e.push_back(lo + (hi - lo) * i / n);
  return e;
}

}  // namespace

void residual_structure(const Evaluator& ev, const WindowSet& ws, DiscrepancyReport* report) {
  const ExtendedPredictor& pred = ev.predictor();
  const ModelExtensions nominal;
  std::vector<Eigen::Vector2d> predicted;
  for (const Window& w : ws.windows) {
    pred.predict(*w.xi, nominal, *w.timeline, w.start, w.times, &predicted);
    for (size_t k = 0; k < w.times.size(); ++k) {
      const OrientedField f =
          pred.field().at(pred.field_orientation(nominal, *w.timeline, w.times[k]));
      ResidualSample r;
      r.p_W = w.measured[k];
      const Eigen::Vector2d d = w.measured[k] - f.stagnation_point();
      r.distance_m = d.norm();
      const double pan = f.orientation().pan_rad;
      double alpha = std::atan2(d.y(), d.x()) - pan;
      alpha = std::remainder(alpha, 2.0 * kPi);
      r.alpha_deg = rad_to_deg(alpha);
      r.since_change_s = w.since_change_s[k];
      const size_t a = k == 0 ? 0 : k - 1, b = std::min(k + 1, w.times.size() - 1);
      const Eigen::Vector2d pa = k == 0 ? w.start.p_W : w.measured[a];
      const double ta = k == 0 ? w.start.t_s : w.times[a];
      if (w.times[b] > ta) r.speed_mps = (w.measured[b] - pa).norm() / (w.times[b] - ta);
      const Eigen::Vector2d e = predicted[k] - w.measured[k];
      const Eigen::Vector2d er =
          r.distance_m > 0.0 ? Eigen::Vector2d(d / r.distance_m) : Eigen::Vector2d(1.0, 0.0);
      r.radial_m = e.dot(er);
      r.tangential_m = e.dot(Eigen::Vector2d(-er.y(), er.x()));
      report->residuals.push_back(r);
    }
  }
  const auto& s = report->residuals;
  report->residual_bins["distance_from_s_m"] =
      bin_residuals(s, edges(0.0, 1.2, 12), [](const ResidualSample& r) { return r.distance_m; });
  report->residual_bins["alpha_deg"] = bin_residuals(
      s, edges(-180.0, 180.0, 12), [](const ResidualSample& r) { return r.alpha_deg; });
  report->residual_bins["time_since_command_s"] = bin_residuals(
      s, edges(0.0, 2.0, 8), [](const ResidualSample& r) { return r.since_change_s; });
  report->residual_bins["speed_mps"] =
      bin_residuals(s, edges(0.0, 2.0, 8), [](const ResidualSample& r) { return r.speed_mps; });
  report->residual_bins["x_m"] =
      bin_residuals(s, edges(-1.5, 1.5, 6), [](const ResidualSample& r) { return r.p_W.x(); });
  report->residual_bins["y_m"] =
      bin_residuals(s, edges(-1.5, 1.5, 6), [](const ResidualSample& r) { return r.p_W.y(); });
}

}  // namespace airtwin::discrepancy_detail
