// airtwin view: a scenario in closed loop, shown live in a window (docs/viewer.md). The run is
// `airtwin run`'s (runs/scenario_run.h, the same flags, seed and decisions); each camera frame
// goes to the window program `airtwin-viewer`, a separate executable beside this one, which draws
// it with MuJoCo's renderer in a GLFW window and paces the run (pause, step, speed).

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "app/cli_common.h"
#include "app/commands.h"
#include "app/run_setup.h"
#include "common/errors.h"
#include "runs/run_view.h"
#include "runs/scenario_run.h"
#include "scenes/scenario.h"
#include "viewer/viewer_process.h"

namespace airtwin::cli {
namespace {

struct ViewArgs {
  std::string scenario;
  RunSetupFlags setup;
  uint64_t seed = 0;
  std::string camera;
  bool no_overlay = false;
  bool paused = false;
  double speed = 1.0;
  int width = 1024, height = 1024;
  int64_t steps = 0;
  std::string screenshot;
};

// The window program: `airtwin-viewer` in this executable's folder.
std::string viewer_program() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  const std::filesystem::path program =
      (error ? std::filesystem::path(".") : self.parent_path()) / "airtwin-viewer";
  if (::access(program.c_str(), X_OK) != 0) {
    throw InputError("the window program " + program.string() +
                     " is missing (it is built with airtwin: cmake --build BUILD --target "
                     "airtwin-viewer)");
  }
  return program.string();
}

// A scratch folder for the --vision camera calibration, removed with this object.
struct ScratchDir {
  std::filesystem::path path;
  ScratchDir()
      : path(std::filesystem::temp_directory_path() /
             ("airtwin-view-" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

void run_view(const ViewArgs& a) {
  // Flags first, then the scenario and --mjcf's scene, then the display: nothing opens for a run
  // that cannot start.
  check_run_setup_flags(a.setup);
  if (!(a.speed >= 1.0 / 64.0 && a.speed <= 64.0)) {
    throw UsageError("--speed must be in [1/64, 64], got " + std::to_string(a.speed));
  }
  if (a.width < 16 || a.height < 16) throw UsageError("--width and --height must be >= 16 px");
  if (a.steps < 0) throw UsageError("--steps must be >= 0");
  if (!a.screenshot.empty() && a.steps == 0) throw UsageError("--screenshot needs --steps N");
  const Scenario scenario = read_scenario(a.scenario);
  const AirFieldModel field = field_model_of(a.setup);
  ScenarioRunOptions options = run_options_of(a.setup);
  options.seed = a.seed;
  check_user_scene(a.setup, scenario, options);
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') {
    throw InputError(
        "no display: DISPLAY is not set, and `view` opens a window (on a machine without a "
        "screen: Xvfb :1 & DISPLAY=:1 airtwin view ...)");
  }
  if (!a.screenshot.empty()) ensure_parent_dir(a.screenshot);

  // The window process, started before the run so that a window that cannot open fails first.
  const std::string caption = scenario.name + " seed " + std::to_string(a.seed);
  std::vector<std::string> window_args = {
      "--title",  "airtwin view: " + caption, "--width", std::to_string(a.width),
      "--height", std::to_string(a.height),   "--speed", std::to_string(a.speed)};
  if (!a.camera.empty()) window_args.insert(window_args.end(), {"--camera", a.camera});
  if (a.no_overlay) window_args.push_back("--no-overlay");
  if (a.paused) window_args.push_back("--paused");
  if (a.steps > 0) window_args.insert(window_args.end(), {"--steps", std::to_string(a.steps)});
  if (!a.screenshot.empty()) window_args.insert(window_args.end(), {"--screenshot", a.screenshot});
  ViewerProcess viewer(viewer_program(), window_args);

  std::unique_ptr<ScratchDir> scratch;
  if (a.setup.vision) {
    // Without --calib the twin's camera is calibrated as `run --vision` does, in a scratch folder.
    scratch = std::make_unique<ScratchDir>();
    options.vision_camera = vision_camera_of(a.setup, options, scratch->path.string(), a.seed);
  }
  RunView view(viewer, scenario.task, caption);
  options.on_frame = [&](const Twin& twin, int64_t frame,
                         const std::vector<DecisionRecord>& decisions) {
    view.on_frame(twin, frame, decisions);
  };
  try {
    const ScenarioRunResult result = run_scenario(scenario, field, options);
    char verdict[256];
    if (result.success && result.loop.completion_time_s) {
      std::snprintf(verdict, sizeof(verdict), "success in %.1f s", *result.loop.completion_time_s);
    } else {
      std::snprintf(verdict, sizeof(verdict), "FAILED at t = %.1f s (%d/%d objects in zone)",
                    view.last_time_s(), result.objects_in_zone, result.n_objects);
    }
    std::printf("%s: %s\n", caption.c_str(), verdict);
    std::fflush(stdout);
    viewer.finish(verdict);
  } catch (const ViewClosed&) {
    std::printf("%s: window closed at t = %.3f s (%lld frames shown)\n", caption.c_str(),
                view.last_time_s(), static_cast<long long>(view.frames_shown()));
  }
  if (!a.screenshot.empty()) std::printf("wrote %s\n", a.screenshot.c_str());
}

}  // namespace

void add_view_command(CLI::App& app) {
  auto args = std::make_shared<ViewArgs>();
  CLI::App* sub = app.add_subcommand(
      "view",
      "Show a scenario live in a window as the controller steers it in closed loop: the run of\n"
      "'airtwin run' (same flags, seed and decisions), drawn by MuJoCo's renderer with the air on\n"
      "the floor as arrows coloured by speed, the stagnation point s (red), the path (green) and\n"
      "zones. Keys: space pause, right arrow step one camera frame (25 ms) while paused, + / -\n"
      "speed x2 / x0.5, C camera, O overlay, Esc quit; mouse: left drag rotate, right drag move,\n"
      "wheel zoom. Needs a display (DISPLAY). docs/viewer.md.");
  sub->add_option("scenario", args->scenario, "Scenario file (YAML)")->required();
  sub->add_option("--seed", args->seed, "Seed of the twin and the controller")
      ->capture_default_str();
  sub->add_option("--camera", args->camera,
                  "Start with this fixed camera of the model (top: the twin's camera) instead of "
                  "the free camera");
  sub->add_flag("--no-overlay", args->no_overlay, "Start with the overlay hidden (O shows it)");
  sub->add_flag("--paused", args->paused,
                "Start paused on the first frame (space runs, right arrow steps)");
  sub->add_option("--speed", args->speed, "Real-time factor asked for, in [1/64, 64]")
      ->capture_default_str();
  sub->add_option("--width", args->width, "Window width (px)")->capture_default_str();
  sub->add_option("--height", args->height, "Window height (px)")->capture_default_str();
  sub->add_option("--steps", args->steps,
                  "Stop after N camera frames (25 ms each) past the first and close the window");
  sub->add_option("--screenshot", args->screenshot,
                  "With --steps: save the window's picture (scene and overlay, no text) as PNG");
  add_run_setup_flags(sub, args->setup,
                      "calibrate the twin's camera (in a temporary folder, removed after)");
  sub->callback([args] { run_view(*args); });
}

}  // namespace airtwin::cli
