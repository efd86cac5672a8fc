#pragma once
// The live viewer's window as seen from the simulation: a child process (`airtwin-viewer`, its
// own executable, see docs/viewer.md for why) started with a socket to talk over
// (viewer/viewer_channel.h). The simulation sends it the model once and every camera frame, and
// waits for it after each: the window decides when the run goes on (pause, step, speed).

#include <sys/types.h>

#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include "viewer/view_frame.h"
#include "viewer/viewer_channel.h"

namespace airtwin {

class ViewerProcess {
 public:
  /// Starts `program` with `args` followed by "--fd N" (its end of the socket) and waits until
  /// its window is open. Throws ViewerError with the window's own reason (no display, no OpenGL)
  /// or when the program cannot be started or ends first.
  ViewerProcess(const std::string& program, const std::vector<std::string>& args);
  /// Closes the socket (the window process then ends) and reaps the process; one that has not
  /// ended after 2 s is terminated.
  ~ViewerProcess();
  ViewerProcess(const ViewerProcess&) = delete;
  ViewerProcess& operator=(const ViewerProcess&) = delete;

  /// Sends the model the frames are states of (once, before the first frame).
  void send_model(const mjModel* m);
  /// Shows `frame` and waits for the window: true when it asks for the next frame, false when it
  /// was closed (Esc, the close button, or its --steps were done). Throws ViewerError when the
  /// window process fails.
  bool show(const ViewFrame& frame);
  /// The run is over: sends `verdict` (one line) and waits until the window is closed.
  void finish(const std::string& verdict);

 private:
  int fd_ = -1;
  pid_t pid_ = -1;
  bool closed_ = false;  // the window said kQuit or closed the socket
  // "exited with status N" / "killed by signal N" for the window process once it has ended
  // (waits up to `wait_s` for it), or "still running".
  std::string exit_description(double wait_s);
};

}  // namespace airtwin
