#include "models/speed_pairs.h"

#include <algorithm>
#include <cmath>

#include "common/errors.h"

namespace airtwin {
namespace {

double median_of(std::vector<double> x) {
  if (x.empty()) return 0.0;
  const size_t m = x.size() / 2;
  std::nth_element(x.begin(), x.begin() + m, x.end());
  return x[m];
}

// Where the neighbours of frame k put it: the quadratic in time through the 3-frame subset of the
// frames within +-3 (shifted inward at the ends) that best explains the others (least median of
// squares), so that up to two glitched neighbours cannot spoil the prediction. Smooth motion is
// followed to about jerk x dt^3 (well under a millimetre at 40 Hz).
Eigen::Vector2d robust_prediction(const std::vector<TrajectorySample>& s, size_t k) {
  const long n = static_cast<long>(s.size());
  long lo = static_cast<long>(k) - 3, hi = static_cast<long>(k) + 3;
  if (lo < 0) hi = std::min(n - 1, hi - lo), lo = 0;
  if (hi > n - 1) lo = std::max(0L, lo - (hi - (n - 1))), hi = n - 1;
  std::vector<long> nb;
  for (long i = lo; i <= hi; ++i)
    if (i != static_cast<long>(k)) nb.push_back(i);
  const double tk = s[k].t_s;
  double best_score = INFINITY;
  Eigen::Vector2d best = s[k].p_W;
  std::vector<double> residuals(nb.size());
  for (size_t a = 0; a < nb.size(); ++a) {
    for (size_t b = a + 1; b < nb.size(); ++b) {
      for (size_t c = b + 1; c < nb.size(); ++c) {
        const double ta = s[nb[a]].t_s, tb = s[nb[b]].t_s, tc = s[nb[c]].t_s;
        // Lagrange quadratic through the three frames, evaluated at time t.
        auto at = [&](double t) -> Eigen::Vector2d {
          const double la = (t - tb) * (t - tc) / ((ta - tb) * (ta - tc));
          const double lb = (t - ta) * (t - tc) / ((tb - ta) * (tb - tc));
          const double lc = (t - ta) * (t - tb) / ((tc - ta) * (tc - tb));
          return la * s[nb[a]].p_W + lb * s[nb[b]].p_W + lc * s[nb[c]].p_W;
        };
        for (size_t m = 0; m < nb.size(); ++m)
          residuals[m] = (s[nb[m]].p_W - at(s[nb[m]].t_s)).norm();
        const double score = median_of(residuals);
        if (score < best_score) best_score = score, best = at(tk);
      }
    }
  }
  return best;
}

}  // namespace

std::vector<size_t> repair_position_glitches(std::vector<TrajectorySample>* samples,
                                             double floor_m) {
  std::vector<TrajectorySample>& s = *samples;
  std::vector<size_t> repaired;
  const size_t n = s.size();
  if (n < 7) return repaired;
  std::vector<Eigen::Vector2d> predicted(n);
  std::vector<double> e(n);
  for (size_t k = 0; k < n; ++k) {
    predicted[k] = robust_prediction(s, k);
    e[k] = (s[k].p_W - predicted[k]).norm();
  }
  const double threshold = std::max(floor_m, 6.0 * 1.4826 * median_of(e));
  for (size_t k = 0; k < n; ++k) {
    if (e[k] > threshold) repaired.push_back(k);
  }
  for (size_t k : repaired) s[k].p_W = predicted[k];
  return repaired;
}

SpeedPairs speed_pairs_from_trajectories(const TrajectorySet& set, const AirFieldModel& field,
                                         const SpeedPairOptions& o, SpeedPairReport* report) {
  SpeedPairReport rep;
  // One frame interval for the whole data set.
  std::vector<double> intervals;
  for (const Trajectory& tr : set.trajectories)
    for (size_t k = 1; k < tr.samples.size(); ++k)
      intervals.push_back(tr.samples[k].t_s - tr.samples[k - 1].t_s);
  if (intervals.empty()) throw InputError("identification: no trajectory has two frames");
  const double dt = median_of(intervals);
  for (const Trajectory& tr : set.trajectories) {
    for (size_t k = 1; k < tr.samples.size(); ++k) {
      const double step = tr.samples[k].t_s - tr.samples[k - 1].t_s;
      if (std::abs(step - dt) > 0.01 * dt) {
        throw InputError("identification: trajectory '" + tr.id + "' has a frame interval of " +
                         std::to_string(step) + " s at t = " + std::to_string(tr.samples[k].t_s) +
                         " s; all frames must be " + std::to_string(dt) + " s apart (within 1%)");
      }
    }
  }

  std::vector<double> v, va, vn, van;
  for (const Trajectory& tr : set.trajectories) {
    ++rep.n_trajectories;
    rep.n_frames += tr.samples.size();
    if (tr.samples.size() < 4) {
      ++rep.n_short_trajectories;
      continue;
    }
    std::vector<TrajectorySample> s = tr.samples;
    if (o.repair_glitches) {
      rep.n_glitches_repaired += repair_position_glitches(&s, o.glitch_floor_m).size();
    }
    // Central-difference speeds and the air speed at each interior frame.
    const size_t n = s.size();
    std::vector<double> speed(n, 0.0), air(n, 0.0);
    for (size_t k = 1; k + 1 < n; ++k) {
      speed[k] = (s[k + 1].p_W - s[k - 1].p_W).norm() / (2.0 * dt);
      air[k] = field.at(s[k].nozzle).speed(s[k].p_W);
      ++rep.n_samples;
      if (speed[k] < o.stationary_speed_mps) ++rep.n_dropped;
    }
    for (size_t k = 1; k + 2 < n; ++k) {
      if (speed[k] < o.stationary_speed_mps || speed[k + 1] < o.stationary_speed_mps) continue;
      v.push_back(speed[k]);
      va.push_back(air[k]);
      vn.push_back(speed[k + 1]);
      van.push_back(air[k + 1]);
    }
  }
  SpeedPairs d;
  d.dt_s = dt;
  d.v = Eigen::Map<Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
  d.va = Eigen::Map<Eigen::VectorXd>(va.data(), static_cast<Eigen::Index>(va.size()));
  d.v_next = Eigen::Map<Eigen::VectorXd>(vn.data(), static_cast<Eigen::Index>(vn.size()));
  d.va_next = Eigen::Map<Eigen::VectorXd>(van.data(), static_cast<Eigen::Index>(van.size()));
  rep.n_pairs = v.size();
  if (report) *report = rep;
  return d;
}

}  // namespace airtwin
