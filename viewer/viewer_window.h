#pragma once
// The live viewer's window (`airtwin-viewer`): a GLFW window with an OpenGL (GLX) context in
// which MuJoCo's own renderer (mjr_render on mjvScene, mjvCamera, mjvOption) draws the twin as the
// simulation (`airtwin view`) sends it, frame by frame, over a socket (viewer/viewer_channel.h),
// plus the overlay: the air on the floor as arrows coloured by speed, the stagnation point s, the
// task's path, reference points and zones (viewer/view_frame.h). The scene looks as the camera
// frames do (sim/scene_look.h).
//
// The window paces the run: space pauses, the right arrow steps one camera frame (25 ms of
// simulated time) while paused, + and - double and halve the speed (the asked and the measured
// real-time factors are shown), the mouse moves the camera as MuJoCo's simulate does (left drag
// rotates, right drag moves, middle drag or the wheel zooms; shift for the horizontal variants),
// C cycles between the free camera and the model's fixed cameras, O hides or shows the overlay,
// Esc or the close button quits. The window's title carries the state after `title`: simulated
// time, paused or running, the asked speed, the camera and the overlay ("airtwin view: line seed 1
// | 0.075 s | paused | x1 | camera top | overlay on"), for a task bar and for scripts.
//
// This code runs in its own process, which links GLFW (and through it the system's libGL) and
// never OSMesa: MuJoCo 2.2's GL loader takes the first of EGL, OSMesa and GLX it finds in the
// process, so the offscreen renderer and a window cannot share one process (docs/viewer.md).

#include <cstdint>
#include <string>

namespace airtwin {

struct ViewerWindowOptions {
  int width_px = 1024;  ///< window size (px); the framebuffer may differ on HiDPI screens
  int height_px = 1024;
  std::string title = "airtwin view";
  /// A fixed camera of the model to start with ("top": the twin's camera), or empty for the free
  /// camera (an oblique view of the floor).
  std::string camera;
  bool overlay = true;  ///< draw the overlay (the O key toggles it)
  bool paused = false;  ///< start paused, on the first frame (space runs, the right arrow steps)
  double speed = 1.0;   ///< asked real-time factor, in [1/64, 64]
  /// > 0: after this many camera frames past the first (or at the run's end, if sooner) save
  /// `screenshot` and quit.
  int64_t steps = 0;
  /// PNG of the window's picture (the scene and the overlay; not the text) when `steps` are done.
  std::string screenshot;
};

/// Opens the window and runs it on socket `fd` until it is closed, its steps are done or the
/// simulation goes away. Reports kReady or kError to the simulation first. Throws InputError for
/// bad options, ViewerError when the window cannot be opened or the simulation breaks the
/// protocol (in both cases the simulation has been told why, where it can still be told).
void run_viewer_window(int fd, const ViewerWindowOptions& options);

}  // namespace airtwin
