#pragma once
// The live view of a closed-loop run (`airtwin view`): every camera frame of the run goes to the
// viewer's window process (viewer/viewer_process.h) as its kinematic state and overlay
// (viewer/view_frame.h): the task's path and reference points or its zones, the reference being
// steered to, the stagnation point s, and the twin's mean air on a floor grid. The run itself is
// runs/scenario_run.h's, unchanged: the view is its on_frame observer, and it waits for the window
// after each frame, so the window paces the run (pause, step, speed).

#include <Eigen/Core>
#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include "controller/closed_loop.h"
#include "controller/task.h"
#include "sim/twin.h"
#include "viewer/view_frame.h"
#include "viewer/viewer_process.h"

namespace airtwin {

/// The window was closed (or its steps were done) while the run went on: thrown from on_frame
/// to stop the run where it is.
class ViewClosed : public std::exception {
 public:
  const char* what() const noexcept override { return "the viewer window was closed"; }
};

/// The floor grid the air is shown on: every `spacing_m` over the square of half-width
/// `half_width_m` around the point below the nozzle (the top camera's 2.7 m by default).
std::vector<Eigen::Vector2d> air_grid(double half_width_m = 1.35, double spacing_m = 0.15);

/// The overlay of the twin's present state: the task's path, reference points and zones, the
/// last decision's reference, the stagnation point (while the jet runs), the twin's
/// mean air at 5 mm above each `grid` point (sim/air_forces.h mean_air), and `caption`.
ViewOverlay view_overlay(const Twin& twin, const TaskSpec& task,
                         const std::vector<DecisionRecord>& decisions,
                         const std::vector<Eigen::Vector2d>& grid, const std::string& caption);

class RunView {
 public:
  /// Sends the frames of a run of `task` to `viewer` (which must outlive this), the caption
  /// followed by the decision count.
  RunView(ViewerProcess& viewer, const TaskSpec& task, const std::string& caption);

  /// One camera frame: the model first (once), then the frame; waits for the window. Throws
  /// ViewClosed when the window was closed, ViewerError when it failed.
  void on_frame(const Twin& twin, int64_t frame_index,
                const std::vector<DecisionRecord>& decisions);

  /// The frames the window received so far (at high speeds it draws only the latest of those
  /// that arrive within one screen refresh) and the simulated time of the last one (s). The
  /// window asks for a frame before it reads the one already sent, so the frame being waited on
  /// when it closes was never read.
  int64_t frames_shown() const { return frames_shown_; }
  double last_time_s() const { return last_shown_time_s_; }

 private:
  ViewerProcess& viewer_;
  TaskSpec task_;
  std::string caption_;
  std::vector<Eigen::Vector2d> grid_;
  bool model_sent_ = false;
  int64_t frames_shown_ = 0;
  double last_shown_time_s_ = 0.0;
};

}  // namespace airtwin
