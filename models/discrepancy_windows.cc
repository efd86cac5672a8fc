#include "models/discrepancy_windows.h"

#include <algorithm>
#include <cmath>

#include "common/errors.h"
#include "models/trajectory_replay.h"

namespace airtwin::discrepancy_detail {
namespace {

// The prior command is placed this long before the first sample: the timeline needs strictly
// increasing times, and the servos rest at it until the first sample's command.
constexpr double kPriorLead_s = 1.0;

bool same_command(const NozzleOrientation& a, const NozzleOrientation& b) {
  return a.pan_rad == b.pan_rad && a.tilt_rad == b.tilt_rad;
}

}  // namespace

WindowSet make_windows(const TrajectorySet& set,
                       const std::map<std::string, ObjectDynamics>& objects,
                       const DiscrepancyOptions& o) {
  WindowSet ws;
  for (size_t ti = 0; ti < set.trajectories.size(); ++ti) {
    const Trajectory& tr = set.trajectories[ti];
    const auto xi = objects.find(tr.object);
    if (xi == objects.end()) {
      std::string known;
      for (const auto& [name, d] : objects) known += (known.empty() ? "" : ", ") + name;
      throw InputError("trajectory " + tr.id + ": no eq. (8) coefficients for object type '" +
                       tr.object + "' (known: " + known + ")");
    }
    const std::vector<TrajectorySample>& s = tr.samples;
    if (s.size() < kStartFrames) {
      ++ws.n_short;
      continue;
    }
    // The recorded command history: the first command, then every change; before it the prior
    // command when one is given (the servos travel from it from the first sample on).
    std::vector<TimedCommand> commands;
    if (o.prior_command && !same_command(*o.prior_command, s.front().nozzle)) {
      commands.push_back({s.front().t_s - kPriorLead_s, *o.prior_command});
    }
    commands.push_back({s.front().t_s, s.front().nozzle});
    for (size_t k = 1; k < s.size(); ++k) {
      if (!same_command(s[k].nozzle, s[k - 1].nozzle)) commands.push_back({s[k].t_s, s[k].nozzle});
      ws.tilts_deg.insert(tilt_group_deg(s[k].nozzle.tilt_rad));
    }
    ws.tilts_deg.insert(tilt_group_deg(s.front().nozzle.tilt_rad));
    ws.timelines.push_back(std::make_unique<NozzleTimeline>(o.nozzle, commands, s.back().t_s));
    const NozzleTimeline* timeline = ws.timelines.back().get();

    size_t i0 = 0;
    while (i0 + 1 < s.size()) {
      size_t i1 = i0;
      while (i1 + 1 < s.size() && s[i1 + 1].t_s <= s[i0].t_s + o.window_s + 1e-9) ++i1;
      if (i1 == i0) {
        ++i0;
        continue;
      }
      if (s[i1].t_s - s[i0].t_s < o.min_window_s - 1e-9 || i1 - i0 + 1 < kStartFrames) {
        ++ws.n_short;
        i0 = i1;
        continue;
      }
      Window w;
      w.trajectory = ti;
      w.xi = &xi->second;
      w.type = &xi->first;
      w.timeline = timeline;
      const StartFit fit = fit_start(s, i0);
      w.start.t_s = s[i0].t_s;
      w.start.p_W = fit.p_W;
      w.start.v_W = fit.v_W;
      Eigen::Vector2d last = fit.p_W;
      for (size_t k = i0 + o.residual_stride; k <= i1; k += o.residual_stride) {
        if (k + o.residual_stride > i1) k = i1;  // the window's last frame always counts
        w.times.push_back(s[k].t_s);
        w.measured.push_back(s[k].p_W);
        w.path_m += (s[k].p_W - last).norm();
        last = s[k].p_W;
        double change = commands.front().t_s;
        for (const TimedCommand& c : commands) {
          if (c.t_s <= s[k].t_s) change = c.t_s;
        }
        w.since_change_s.push_back(s[k].t_s - change);
      }
      w.scale_m = std::max(kMinScale_m, w.path_m);
      // The field's orientation moves inside the window, or within a plausible lag before it.
      w.command_changes =
          !timeline->at_rest_between(w.start.t_s - o.nozzle.transit_delay_s - 1.5, s[i1].t_s);
      ws.windows.push_back(std::move(w));
      i0 = i1;
    }
  }
  return ws;
}

}  // namespace airtwin::discrepancy_detail
