#include "models/speed_pairs.h"

#include <algorithm>
#include <cmath>

#include "common/errors.h"
#include "common/units.h"
#include "models/savitzky_golay.h"

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

// Why a moving sample is not used (stationary ones are counted apart).
constexpr char kUsable = 0, kOffRadial = 1, kTransient = 2;

// Collects regression pairs from speed series, one moving stretch at a time.
struct PairBuilder {
  std::vector<double> v, va, vn, van;

  // Splits a series into runs of consecutive moving samples (speed >= the stationary threshold),
  // smooths each run on its own (so no stop or start is smeared into the motion), and keeps the
  // pairs (k, k+1) inside a run whose smoothed speeds stay above the threshold.
  void add_series(std::span<const double> speed, std::span<const double> air,
                  const SpeedPairOptions& o, SpeedPairReport* rep,
                  std::span<const char> excluded = {}) {
    const size_t n = speed.size();
    rep->n_samples += n;
    auto moving = [&](size_t i) {
      return speed[i] >= o.stationary_speed_mps && (excluded.empty() || !excluded[i]);
    };
    size_t k = 0;
    while (k < n) {
      if (!moving(k)) {
        if (speed[k] < o.stationary_speed_mps)
          ++rep->n_dropped;
        else if (excluded[k] == kTransient)
          ++rep->n_transient;
        else
          ++rep->n_off_radial;
        ++k;
        continue;
      }
      size_t end = k;
      while (end < n && moving(end)) ++end;
      const std::vector<double> smooth =
          savitzky_golay(speed.subspan(k, end - k), o.smoothing_half_window, o.smoothing_order);
      for (size_t i = 0; i < smooth.size(); ++i) {
        if (smooth[i] < o.stationary_speed_mps) ++rep->n_dropped;
      }
      for (size_t i = 0; i + 1 < smooth.size(); ++i) {
        if (smooth[i] < o.stationary_speed_mps || smooth[i + 1] < o.stationary_speed_mps) continue;
        v.push_back(smooth[i]);
        va.push_back(air[k + i]);
        vn.push_back(smooth[i + 1]);
        van.push_back(air[k + i + 1]);
      }
      k = end;
    }
  }

  SpeedPairs finish(double dt_s) {
    SpeedPairs d;
    d.dt_s = dt_s;
    auto map = [](std::vector<double>& x) {
      return Eigen::Map<Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size()));
    };
    d.v = map(v);
    d.va = map(va);
    d.v_next = map(vn);
    d.va_next = map(van);
    return d;
  }
};

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

  // Glitch repair first: a glitch would spoil the noise estimate and the smoothing below.
  std::vector<std::vector<TrajectorySample>> repaired;
  for (const Trajectory& tr : set.trajectories) {
    ++rep.n_trajectories;
    rep.n_frames += tr.samples.size();
    if (tr.samples.size() < 4) {
      ++rep.n_short_trajectories;
      continue;
    }
    repaired.push_back(tr.samples);
    if (o.repair_glitches) {
      rep.n_glitches_repaired +=
          repair_position_glitches(&repaired.back(), o.glitch_floor_m).size();
    }
  }

  // Detection noise, pooled over the data set (one camera): fourth differences remove motion up to
  // cubic order (what is left of it at 40 Hz is ~0.03 mm) and leave 70 sigma^2 of white noise;
  // their median absolute value is robust to the few kinks where an object starts or stops.
  std::vector<double> d4;
  for (const auto& s : repaired) {
    for (size_t k = 2; k + 2 < s.size(); ++k) {
      const Eigen::Vector2d d =
          s[k - 2].p_W - 4 * s[k - 1].p_W + 6 * s[k].p_W - 4 * s[k + 1].p_W + s[k + 2].p_W;
      d4.push_back(std::abs(d.x()));
      d4.push_back(std::abs(d.y()));
    }
  }
  rep.position_noise_m = d4.empty() ? 0.0 : 1.4826 * median_of(d4) / std::sqrt(70.0);
  const bool denoise =
      o.smoothing_half_window > 0 && rep.position_noise_m > o.position_noise_floor_m;
  rep.positions_smoothed = denoise;

  // The speed noise (per axis) that remains after the differences below, and from it the speed
  // under which a sample is indistinguishable from rest: a resting object's measured speed is
  // Rayleigh distributed and exceeds 3.5 sigma in 0.2% of the frames.
  double gain = std::sqrt(2.0) / (2.0 * dt);  // central difference of raw positions
  if (denoise) {
    const int m = o.smoothing_half_window, len = 2 * m + 1;
    const std::vector<double> w = savitzky_golay_weights(len, m, o.smoothing_order);
    std::vector<double> c(len + 2, 0.0);  // (smooth(p)_{k+1} - smooth(p)_{k-1}) / (2 dt)
    for (int j = 0; j < len; ++j) {
      c[j + 2] += w[j] / (2.0 * dt);
      c[j] -= w[j] / (2.0 * dt);
    }
    gain = 0.0;
    for (double cj : c) gain += cj * cj;
    gain = std::sqrt(gain);
  }
  const double speed_noise = rep.position_noise_m * gain;
  rep.stationary_speed_mps = std::max(o.stationary_speed_mps, 3.5 * speed_noise);
  SpeedPairOptions run_options = o;
  run_options.stationary_speed_mps = rep.stationary_speed_mps;

  PairBuilder pairs;
  size_t i = 0;
  for (const Trajectory& tr : set.trajectories) {
    if (tr.samples.size() < 4) continue;
    std::vector<TrajectorySample>& s = repaired[i++];
    const size_t n = s.size();
    if (denoise) {
      std::vector<double> x(n), y(n);
      for (size_t k = 0; k < n; ++k) x[k] = s[k].p_W.x(), y[k] = s[k].p_W.y();
      x = savitzky_golay(x, o.smoothing_half_window, o.smoothing_order);
      y = savitzky_golay(y, o.smoothing_half_window, o.smoothing_order);
      for (size_t k = 0; k < n; ++k) s[k].p_W = {x[k], y[k]};
    }
    // Central-difference speeds and the air speed at each interior frame, and whether the motion
    // is radial from s as eq. (9) says.
    std::vector<double> speed(n - 2), air(n - 2);
    std::vector<char> excluded(n - 2, kUsable);
    const double min_cos = std::cos(o.max_direction_error_rad);
    for (size_t k = 1; k + 1 < n; ++k) {
      const Eigen::Vector2d velocity = (s[k + 1].p_W - s[k - 1].p_W) / (2.0 * dt);
      const OrientedField f = field.at(s[k].nozzle);
      speed[k - 1] = velocity.norm();
      air[k - 1] = f.speed(s[k].p_W);
      const Eigen::Vector2d out = s[k].p_W - f.stagnation_point();
      if (o.max_direction_error_rad < kPi && speed[k - 1] > 0 && out.norm() > 0) {
        if (velocity.dot(out) < min_cos * speed[k - 1] * out.norm()) excluded[k - 1] = kOffRadial;
      }
    }
    // The transient after a command change (and after the first frame, where the recording of a
    // new command starts): the servos are still turning and the jet sweeping, so the air is not
    // the recorded command's. Samples within transient_s of it are not used.
    if (o.transient_s > 0) {
      double change_t = s[0].t_s;
      for (size_t k = 1; k + 1 < n; ++k) {
        if (s[k].nozzle.pan_rad != s[k - 1].nozzle.pan_rad ||
            s[k].nozzle.tilt_rad != s[k - 1].nozzle.tilt_rad) {
          change_t = s[k].t_s;
        }
        if (s[k].t_s - change_t < o.transient_s) excluded[k - 1] = kTransient;
      }
    }
    pairs.add_series(speed, air, run_options, &rep, excluded);
  }
  rep.n_pairs = pairs.v.size();
  if (report) *report = rep;
  return pairs.finish(dt);
}

SpeedPairs speed_pairs_from_series(const SpeedSeries& series, const SpeedPairOptions& o,
                                   SpeedPairReport* report) {
  SpeedPairReport rep;
  rep.n_trajectories = 1;
  rep.n_frames = series.size();
  // The noise of v from its fourth differences (white noise: variance 70 sigma^2), robust to the
  // kinks where an object starts or stops; a signed sample of a resting object exceeds 3.5 sigma
  // in 0.02 % of the frames.
  const std::vector<double>& v = series.v_mps;
  std::vector<double> d4;
  for (size_t k = 2; k + 2 < v.size(); ++k) {
    d4.push_back(std::abs(v[k - 2] - 4 * v[k - 1] + 6 * v[k] - 4 * v[k + 1] + v[k + 2]));
  }
  // Below 20 differences the median says nothing: no estimate, the option's threshold stands.
  rep.speed_noise_mps = d4.size() < 20 ? 0.0 : 1.4826 * median_of(d4) / std::sqrt(70.0);
  rep.n_negative_speeds = series.n_negative_v;
  rep.stationary_speed_mps = std::max(o.stationary_speed_mps, 3.5 * rep.speed_noise_mps);
  SpeedPairOptions run_options = o;
  run_options.stationary_speed_mps = rep.stationary_speed_mps;
  PairBuilder pairs;
  pairs.add_series(series.v_mps, series.vair_mps, run_options, &rep);
  rep.n_pairs = pairs.v.size();
  if (report) *report = rep;
  return pairs.finish(series.dt_s);
}

}  // namespace airtwin
