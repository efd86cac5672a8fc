#include "models/trajectory_predictor.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/errors.h"
#include "common/text.h"
#include "common/units.h"

namespace airtwin {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMaxSamplesPerObject = 1e6;

void validate_objects(std::span<const ObjectDynamics> dynamics,
                      std::span<const ObjectState> start) {
  if (dynamics.size() != start.size()) {
    throw InputError("trajectory prediction: " + std::to_string(dynamics.size()) +
                     " object dynamics but " + std::to_string(start.size()) + " start states");
  }
  for (size_t j = 0; j < start.size(); ++j) {
    const ObjectState& s = start[j];
    if (!(std::isfinite(s.p_W.x()) && std::isfinite(s.p_W.y()))) {
      throw InputError("trajectory prediction: object " + std::to_string(j) +
                       ": position must be finite, got (" + format_number(s.p_W.x()) + ", " +
                       format_number(s.p_W.y()) + ") m");
    }
    if (!(std::isfinite(s.v) && s.v >= 0)) {
      throw InputError("trajectory prediction: object " + std::to_string(j) +
                       ": speed must be finite and >= 0 (eq. 9 moves objects only away from s), "
                       "got " +
                       format_number(s.v) + " m/s");
    }
    const ObjectDynamics& xi = dynamics[j];
    if (!(std::isfinite(xi.xi1) && std::isfinite(xi.xi2) && std::isfinite(xi.xi3))) {
      throw InputError("trajectory prediction: object " + std::to_string(j) +
                       ": eq. (8) coefficients must be finite");
    }
  }
}

void validate_options(const PredictionOptions& o) {
  if (!(std::isfinite(o.horizon_s) && o.horizon_s > 0)) {
    throw InputError("trajectory prediction: horizon must be finite and > 0 s, got " +
                     format_number(o.horizon_s));
  }
  if (!(std::isfinite(o.sample_rate_hz) && o.sample_rate_hz >= 0)) {
    throw InputError("trajectory prediction: sample rate must be finite and >= 0 Hz, got " +
                     format_number(o.sample_rate_hz));
  }
  if (o.horizon_s * o.sample_rate_hz > kMaxSamplesPerObject) {
    throw InputError("trajectory prediction: horizon " + format_number(o.horizon_s) + " s at " +
                     format_number(o.sample_rate_hz) + " Hz exceeds 1e6 samples per object");
  }
}

}  // namespace

void TrajectoryPredictor::predict(const AirFieldModel& model, const OrientationSchedule& schedule,
                                  std::span<const ObjectDynamics> dynamics,
                                  std::span<const ObjectState> start,
                                  const PredictionOptions& options, Prediction& out) const {
  validate_options(options);
  // The schedule: non-empty, finite, strictly increasing, defined at t = 0.
  if (schedule.empty()) throw InputError("orientation schedule: empty, expected >= 1 entry");
  for (size_t i = 0; i < schedule.size(); ++i) {
    const double t = schedule[i].t_start_s;
    if (!std::isfinite(t)) {
      throw InputError("orientation schedule: entry " + std::to_string(i) +
                       ": t_start must be finite, got " + format_number(t));
    }
    if (i > 0 && !(t > schedule[i - 1].t_start_s)) {
      throw InputError("orientation schedule: entry " + std::to_string(i) + ": t_start " +
                       format_number(t) + " s must be greater than the previous " +
                       format_number(schedule[i - 1].t_start_s) + " s");
    }
  }
  if (!(schedule.front().t_start_s <= 0)) {
    throw InputError("orientation schedule: the first entry starts at " +
                     format_number(schedule.front().t_start_s) +
                     " s, so no orientation is defined at t = 0");
  }
  // The entries that act within [0, horizon): the last one starting at or before 0, then the
  // ones starting inside the horizon. model.rays_at() validates each orientation; the rays are
  // all a ray-following predictor needs, and the others build the full field per segment.
  size_t first = 0;
  while (first + 1 < schedule.size() && schedule[first + 1].t_start_s <= 0) ++first;
  std::vector<OrientedRays> rays;
  std::vector<double> starts;
  rays.reserve(schedule.size() - first);
  starts.reserve(schedule.size() - first);
  for (size_t i = first;
       i < schedule.size() && (i == first || schedule[i].t_start_s < options.horizon_s); ++i) {
    try {
      rays.push_back(model.rays_at(schedule[i].orientation));
    } catch (const InputError& e) {
      throw InputError("orientation schedule: entry " + std::to_string(i) + ": " + e.what());
    }
    starts.push_back(i == first ? 0.0 : schedule[i].t_start_s);
  }
  run({}, rays, starts, dynamics, start, options, out);
}

void TrajectoryPredictor::predict(const OrientedField& field,
                                  std::span<const ObjectDynamics> dynamics,
                                  std::span<const ObjectState> start,
                                  const PredictionOptions& options, Prediction& out) const {
  validate_options(options);
  const double t0 = 0.0;
  run(std::span<const OrientedField>(&field, 1), {}, std::span<const double>(&t0, 1), dynamics,
      start, options, out);
}

void TrajectoryPredictor::predict(const OrientedRays& rays,
                                  std::span<const ObjectDynamics> dynamics,
                                  std::span<const ObjectState> start,
                                  const PredictionOptions& options, Prediction& out) const {
  validate_options(options);
  const double t0 = 0.0;
  run({}, std::span<const OrientedRays>(&rays, 1), std::span<const double>(&t0, 1), dynamics, start,
      options, out);
}

Prediction TrajectoryPredictor::predict(const AirFieldModel& model,
                                        const OrientationSchedule& schedule,
                                        std::span<const ObjectDynamics> dynamics,
                                        std::span<const ObjectState> start,
                                        const PredictionOptions& options) const {
  Prediction out;
  predict(model, schedule, dynamics, start, options, out);
  return out;
}

Prediction TrajectoryPredictor::predict(const OrientedField& field,
                                        std::span<const ObjectDynamics> dynamics,
                                        std::span<const ObjectState> start,
                                        const PredictionOptions& options) const {
  Prediction out;
  predict(field, dynamics, start, options, out);
  return out;
}

Prediction TrajectoryPredictor::predict(const OrientedRays& rays,
                                        std::span<const ObjectDynamics> dynamics,
                                        std::span<const ObjectState> start,
                                        const PredictionOptions& options) const {
  Prediction out;
  predict(rays, dynamics, start, options, out);
  return out;
}

void TrajectoryPredictor::run(std::span<const OrientedField> fields,
                              std::span<const OrientedRays> rays, std::span<const double> starts_s,
                              std::span<const ObjectDynamics> dynamics,
                              std::span<const ObjectState> start, const PredictionOptions& options,
                              Prediction& out) const {
  validate_objects(dynamics, start);
  const size_t m = start.size();
  const double horizon = options.horizon_s;

  // Output buffers (reused when the sizes repeat); the working state is out.end.
  out.n_objects = m;
  out.end.assign(start.begin(), start.end());
  out.rest_since_s.assign(m, kInf);
  out.sample_times_s.clear();
  out.samples.clear();
  if (options.sample_rate_hz > 0) {
    // t_k = k / rate up to the horizon; the relative slack absorbs rounding in horizon * rate.
    const size_t k_max =
        static_cast<size_t>(std::floor(horizon * options.sample_rate_hz * (1 + 1e-12)));
    for (size_t k = 0; k <= k_max; ++k) {
      out.sample_times_s.push_back(
          std::min(static_cast<double>(k) / options.sample_rate_hz, horizon));
    }
    out.samples.resize(out.sample_times_s.size() * m);
    for (size_t j = 0; j < m; ++j) out.samples[j] = start[j];
  }
  if (m == 0) return;

  // Segments of constant orientation; each takes the samples in (t0, t1].
  size_t next_sample = 1;
  const size_t n_segments = fields.empty() ? rays.size() : fields.size();
  for (size_t i = 0; i < n_segments; ++i) {
    const double t0 = i == 0 ? 0.0 : starts_s[i];
    const double t1 = i + 1 < n_segments ? std::min(starts_s[i + 1], horizon) : horizon;
    if (!(t1 > t0)) continue;
    size_t end_sample = next_sample;
    while (end_sample < out.sample_times_s.size() && out.sample_times_s[end_sample] <= t1) {
      ++end_sample;
    }
    Segment seg;
    if (fields.empty()) {
      seg.rays = &rays[i];
    } else {
      seg.field = &fields[i];
    }
    seg.t0_s = t0;
    seg.t1_s = t1;
    seg.sample_times_s =
        std::span<const double>(out.sample_times_s.data() + next_sample, end_sample - next_sample);
    seg.samples = out.samples.empty() ? nullptr : out.samples.data() + next_sample * m;
    advance(seg, dynamics, out.end, out.rest_since_s);
    next_sample = end_sample;
  }
}

}  // namespace airtwin
