// airtwin-viewer: the window of `airtwin view`, started by it (never by hand) with its end of a
// socket. A separate executable because it links GLFW and the system's OpenGL, which MuJoCo 2.2
// cannot drive in the same process as the OSMesa renderer that `airtwin` links (docs/viewer.md).
// Errors reach `airtwin view` over the socket, which prints them as its one line: nothing is
// printed here (but for CLI11's own usage errors, which only a broken caller can cause).

#include <CLI/CLI.hpp>
#include <exception>
#include <string>

#include "common/errors.h"
#include "viewer/viewer_window.h"

int main(int argc, char** argv) {
  CLI::App app{"airtwin-viewer: the window of 'airtwin view' (started by it)."};
  airtwin::ViewerWindowOptions options;
  int fd = -1;
  bool no_overlay = false;
  app.add_option("--fd", fd, "Socket to the simulation")->required();
  app.add_option("--title", options.title, "Window title");
  app.add_option("--width", options.width_px, "Window width (px)");
  app.add_option("--height", options.height_px, "Window height (px)");
  app.add_option("--camera", options.camera, "Fixed camera to start with (default: free)");
  app.add_flag("--no-overlay", no_overlay, "Start with the overlay hidden");
  app.add_flag("--paused", options.paused, "Start paused (space runs, right arrow steps)");
  app.add_option("--speed", options.speed, "Real-time factor asked for");
  app.add_option("--steps", options.steps, "Quit after N camera frames past the first");
  app.add_option("--screenshot", options.screenshot, "PNG written when the steps are done");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  options.overlay = !no_overlay;
  try {
    airtwin::run_viewer_window(fd, options);
  } catch (const std::exception&) {
    return 1;
  }
  return 0;
}
