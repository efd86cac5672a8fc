#include "models/identification.h"

#include <cmath>

#include "common/errors.h"
#include "models/fast_predictor.h"

namespace airtwin {
namespace {

IdentifiedModel from_sindy(const SindyResult& r, const SpeedPairReport& rep, const SpeedPairs& d,
                           const std::string& object, const IdentificationOptions& o) {
  IdentifiedModel m;
  m.object = object;
  m.method = sindy_method_name(o.sindy.method);
  m.coefficients = r.continuous;
  m.discrete = r.discrete;
  m.inclusion = r.inclusion;
  m.r2 = r.r2;
  m.r2_change = r.r2_change;
  m.n_samples = rep.n_samples;
  m.n_dropped = rep.n_dropped;
  m.n_pairs = rep.n_pairs;
  m.n_trajectories = rep.n_trajectories;
  m.n_glitches_repaired = rep.n_glitches_repaired;
  m.n_short_trajectories = rep.n_short_trajectories;
  m.n_off_radial = rep.n_off_radial;
  m.n_transient = rep.n_transient;
  m.transient_s = o.pairs.transient_s;
  m.dt_s = d.dt_s;
  m.lambda = o.sindy.lambda;
  m.library.clear();
  for (int j = 0; j < kSindyTerms; ++j)
    if (o.sindy.terms[j]) m.library.push_back(kTermNames[j]);
  m.bootstraps =
      o.sindy.method == SindyMethod::kEsindy || o.sindy.method == SindyMethod::kRobustEsindy
          ? o.sindy.bootstraps
          : 0;
  m.seed = o.sindy.seed;
  m.smoothing_half_window = o.pairs.smoothing_half_window;
  m.position_noise_m = rep.position_noise_m;
  m.positions_smoothed = rep.positions_smoothed;
  m.stationary_speed_mps = rep.stationary_speed_mps;
  m.speed_noise_mps = rep.speed_noise_mps;
  m.n_negative_speeds = rep.n_negative_speeds;
  return m;
}

}  // namespace

IdentifiedModel identify_trajectories(const TrajectorySet& set, const std::string& object,
                                      const AirFieldModel& field, const IdentificationOptions& o) {
  TrajectorySet selected;
  selected.has_group = set.has_group;
  for (const Trajectory& tr : set.trajectories)
    if (tr.object == object) selected.trajectories.push_back(tr);
  if (selected.trajectories.empty()) {
    throw InputError("identification: no trajectory of object type '" + object + "'");
  }
  SpeedPairReport rep;
  const SpeedPairs d = speed_pairs_from_trajectories(selected, field, o.pairs, &rep);
  IdentifiedModel m = from_sindy(identify_sindy(d, o.sindy), rep, d, object, o);
  for (const Trajectory& tr : selected.trajectories) {
    if (tr.samples.empty()) continue;
    const double tilt_deg = tilt_group_deg(tr.samples.front().nozzle.tilt_rad);
    auto& [moved, all] = m.moved_by_tilt[tilt_deg];
    ++all;
    if ((tr.samples.back().p_W - tr.samples.front().p_W).norm() >= o.replay.min_travel_m) ++moved;
  }

  // The paper's check: predict every trajectory from its first sample, compare the end.
  if (m.is_eq8()) {
    const ReplayReport replay =
        replay_trajectories(selected, field, m.eq8(), FastPredictor(), o.replay);
    if (replay.n_used > 0) m.end_position_mape_pct = replay.mape_pct;
    m.end_position_mape_by_tilt_pct = replay.mape_by_tilt_pct;
    m.end_position_by_sector = replay.by_tilt_sector;
    m.n_mape_trajectories = replay.n_used;
    m.n_mape_excluded = replay.n_excluded;
  }
  return m;
}

IdentifiedModel identify_series(const SpeedSeries& series, const std::string& object,
                                const IdentificationOptions& o) {
  SpeedPairReport rep;
  const SpeedPairs d = speed_pairs_from_series(series, o.pairs, &rep);
  return from_sindy(identify_sindy(d, o.sindy), rep, d, object, o);
}

}  // namespace airtwin
