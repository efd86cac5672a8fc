#include "runs/run_view.h"

#include <cmath>

#include "sim/kinematic_state.h"

namespace airtwin {

namespace {
// The height the air is shown at (m): about a tracer's centre of mass, 3R/8 above its face. The
// CFD's air depends on it (no slip at the floor), the analytical field does not.
constexpr double kAirHeightM = 0.005;
}  // namespace

std::vector<Eigen::Vector2d> air_grid(double half_width_m, double spacing_m) {
  std::vector<Eigen::Vector2d> grid;
  const int n = static_cast<int>(std::floor(half_width_m / spacing_m + 1e-9));
  for (int i = -n; i <= n; ++i) {
    for (int j = -n; j <= n; ++j) grid.emplace_back(i * spacing_m, j * spacing_m);
  }
  return grid;
}

ViewOverlay view_overlay(const Twin& twin, const TaskSpec& task,
                         const std::vector<DecisionRecord>& decisions,
                         const std::vector<Eigen::Vector2d>& grid, const std::string& caption) {
  ViewOverlay o;
  // The task: its path and reference points, or its zones.
  switch (task.kind) {
    case TaskKind::kPath:
      o.path_W = task.path_W;
      o.path_references_W = path_references(task);
      break;
    case TaskKind::kAggregation:
      o.zones.push_back(ViewZone{task.zone.centre_W, task.zone.radius_m, ""});
      break;
    case TaskKind::kSorting:
      for (const auto& [type, zone] : task.zones_by_type) {
        o.zones.push_back(ViewZone{zone.centre_W, zone.radius_m, type});
      }
      break;
  }
  // The controller's last reference, and the stagnation point of the air while the jet runs.
  if (!decisions.empty()) o.current_references_W.push_back(decisions.back().reference_W);
  if (twin.jet_level() > 0.0) o.stagnation_W = twin.stagnation_point();
  // The air the objects are in, on the grid.
  o.air.reserve(grid.size());
  for (const Eigen::Vector2d& p : grid) {
    o.air.push_back(ViewArrow{p, twin.air_forces().mean_air(p, kAirHeightM)});
  }
  o.caption = caption;
  return o;
}

RunView::RunView(ViewerProcess& viewer, const TaskSpec& task, const std::string& caption)
    : viewer_(viewer), task_(task), caption_(caption), grid_(air_grid()) {}

void RunView::on_frame(const Twin& twin, int64_t frame_index,
                       const std::vector<DecisionRecord>& decisions) {
  if (!model_sent_) {
    viewer_.send_model(twin.model());
    model_sent_ = true;
  }
  ViewFrame frame;
  frame.index = frame_index;
  frame.kinematics = capture_kinematics(twin.model(), twin.data());
  frame.overlay = view_overlay(twin, task_, decisions, grid_,
                               caption_ + ", decision " + std::to_string(decisions.size()));
  if (!viewer_.show(frame)) throw ViewClosed();
  // The window asked for more: it has read this frame.
  ++frames_shown_;
  last_shown_time_s_ = twin.time();
}

}  // namespace airtwin
