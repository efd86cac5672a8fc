// `airtwin view` end to end under a real X server (Xvfb): the window's picture after N camera
// frames, drawn by MuJoCo through GLX in the window process, against the offscreen camera frame
// of the same state, drawn by MuJoCo through OSMesa in this process (renders/frame_renderer.h);
// the overlay where the state puts it; bad input as one line and a non-zero exit, never a hang.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "models/air_field.h"
#include "renders/camera_model.h"
#include "renders/frame_renderer.h"
#include "runs/scenario_run.h"
#include "scenes/scenario.h"
#include "tests/app/cli_runner.h"

namespace airtwin {
namespace {

using testing::count_lines;
using testing::run_airtwin;
using testing::scratch_dir;

const std::string& line_file() { return testing::line_with_wide_start(); }
constexpr int64_t kSteps = 20;  // 0.5 s of simulated time: the tracer is moving (~4 mm a frame)

// Where the Xvfb program is, or "" (found on PATH as a shell would).
std::string xvfb_program() {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  size_t start = 0;
  while (start <= dirs.size()) {
    const size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::string candidate = dirs.substr(start, end - start) + "/Xvfb";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
    start = end + 1;
  }
  return "";
}

// A private X server for the test: Xvfb picks a free display number and writes it to a pipe
// (-displayfd), so parallel tests never collide. Stopped (SIGTERM, reaped) with the object.
class Xvfb {
 public:
  explicit Xvfb(const std::string& program) {
    int fds[2];
    if (::pipe(fds) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::close(fds[0]);
      // The server's own chatter (fonts, keyboard maps) stays out of the test's output.
      const int null = ::open("/dev/null", O_WRONLY);
      if (null >= 0) ::dup2(null, STDERR_FILENO);
      const std::string fd = std::to_string(fds[1]);
      // -noreset: by default the server resets when its last client leaves, and a client that
      // connects during the reset (the window after a burst of xdotool calls) is refused.
      ::execl(program.c_str(), "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "1280x1280x24",
              "-nolisten", "tcp", "-noreset", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(fds[1]);
    // The display number, one line, once the server accepts connections.
    std::string line;
    char c = 0;
    while (::read(fds[0], &c, 1) == 1 && c != '\n') line += c;
    ::close(fds[0]);
    if (!line.empty()) display_ = ":" + line;
  }
  ~Xvfb() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  const std::string& display() const { return display_; }

 private:
  pid_t pid_ = -1;
  std::string display_;
};

// The offscreen camera frame (BGR) of frame `index` of `airtwin run scenes/line.yaml --seed 1`,
// and the stagnation point then: the run is stopped there.
struct Reference {
  cv::Mat frame;
  Eigen::Vector2d s_W = Eigen::Vector2d::Zero();
  std::optional<GroundTruthCamera> camera;
};
struct StopRun {};

Reference reference_frame(int64_t index) {
  Reference r;
  const Scenario scenario = read_scenario(line_file());
  ScenarioRunOptions options;
  options.seed = 1;
  std::unique_ptr<FrameRenderer> renderer;
  options.on_frame = [&](const Twin& twin, int64_t frame, const std::vector<DecisionRecord>&) {
    if (frame < index) return;
    renderer = std::make_unique<FrameRenderer>(twin.model());
    r.frame = renderer->render(twin.data(), frame);
    r.s_W = twin.stagnation_point();
    r.camera = GroundTruthCamera::from_model(twin.model());
    throw StopRun{};
  };
  try {
    run_scenario(scenario, AirFieldModel::with_constructed_table(), options);
  } catch (const StopRun&) {
  }
  return r;
}

// Per-pixel comparison of two BGR images of one size.
struct Comparison {
  double mean_abs_diff = 0.0;  // grey levels, over every pixel and channel
  int64_t pixels_differing = 0;
  int64_t pixels_beyond = 0;  // pixels with a channel off by more than kBeyond
  int max_abs_diff = 0;
};
constexpr int kBeyond = 8;
constexpr int64_t kAllowedBeyond = 10;

Comparison compare(const cv::Mat& a, const cv::Mat& b) {
  Comparison c;
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  const cv::Scalar mean = cv::mean(diff);
  c.mean_abs_diff = (mean[0] + mean[1] + mean[2]) / 3.0;
  for (int y = 0; y < diff.rows; ++y) {
    for (int x = 0; x < diff.cols; ++x) {
      const cv::Vec3b& d = diff.at<cv::Vec3b>(y, x);
      const int worst = std::max({d[0], d[1], d[2]});
      c.pixels_differing += worst > 0;
      c.pixels_beyond += worst > kBeyond;
      c.max_abs_diff = std::max(c.max_abs_diff, worst);
    }
  }
  return c;
}

class ViewCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string program = xvfb_program();
    if (program.empty()) {
      GTEST_SKIP() << "Xvfb is not installed (Debian's xvfb package; scripts/setup.sh installs it)";
    }
    xvfb_ = std::make_unique<Xvfb>(program);
    ASSERT_FALSE(xvfb_->display().empty()) << "Xvfb did not start";
    ::setenv("DISPLAY", xvfb_->display().c_str(), 1);
  }
  void TearDown() override { ::unsetenv("DISPLAY"); }

  // `airtwin view scenes/line.yaml --seed 1` in the mirror twin (as the offscreen reference
  // below builds it) for kSteps frames from the top camera, at up to 64x real time; the
  // screenshot read back.
  cv::Mat screenshot(const std::string& extra_flags) {
    const std::string shot = scratch_dir("view_cli") + "/shot.png";
    const testing::CliResult r =
        run_airtwin("view '" + line_file() + "' --seed 1" + testing::mirror_flags() +
                    "--camera top --speed 64 --steps " + std::to_string(kSteps) +
                    " --screenshot '" + shot + "' " + extra_flags);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    char closed[64];
    std::snprintf(closed, sizeof(closed), "window closed at t = %.3f s", kSteps / 40.0);
    EXPECT_NE(r.out.find(closed), std::string::npos) << r.out;
    return cv::imread(shot, cv::IMREAD_COLOR);
  }

  std::unique_ptr<Xvfb> xvfb_;
};

// The window's picture of frame kSteps against the camera frame of the same state: two renderers
// (GLX on Xvfb's llvmpipe in another process, OSMesa's llvmpipe here) on one scene, camera and
// size. Both are Mesa's llvmpipe (one Debian source package), so they agree but for rounding:
// measured, at most 1 grey level in any channel, no pixel beyond 8 (docs/viewer.md). The bounds
// allow ten pixels beyond 8 grey levels (0.001 %: an edge rounded the other way here and there)
// and a mean of 0.01 grey levels; a state one camera frame (25 ms) off already moves the tracer's
// edge by ~74 pixels (0.007 %, checked below), and a wrong look (shadows, another camera, the
// overlay) changes whole regions.
TEST_F(ViewCliTest, ScreenshotMatchesTheOffscreenCameraFrameOfTheSameState) {
  const cv::Mat shot = screenshot("--no-overlay");
  ASSERT_FALSE(shot.empty());
  const Reference ref = reference_frame(kSteps);
  ASSERT_EQ(shot.size(), ref.frame.size());
  const Comparison c = compare(shot, ref.frame);
  std::printf(
      "window vs offscreen: mean |diff| %.5f grey levels, %lld pixels differ, %lld beyond "
      "%d, max %d\n",
      c.mean_abs_diff, static_cast<long long>(c.pixels_differing),
      static_cast<long long>(c.pixels_beyond), kBeyond, c.max_abs_diff);
  EXPECT_LE(c.mean_abs_diff, 0.01);
  EXPECT_LE(c.pixels_beyond, kAllowedBeyond);
  // The bounds can fail: the frame before differs where the tracer moved.
  const Comparison before = compare(shot, reference_frame(kSteps - 1).frame);
  std::printf("window vs the frame before: %lld pixels beyond %d\n",
              static_cast<long long>(before.pixels_beyond), kBeyond);
  EXPECT_GT(before.pixels_beyond, kAllowedBeyond);
}

// With the overlay: s is a red ball where the twin's air has it, and the air's arrows and the
// path change the picture well beyond the clean frame.
TEST_F(ViewCliTest, OverlayDrawsTheStagnationPointAndTheAir) {
  const cv::Mat shot = screenshot("");
  ASSERT_FALSE(shot.empty());
  const Reference ref = reference_frame(kSteps);
  const std::optional<Eigen::Vector2d> uv =
      ref.camera->project(Eigen::Vector3d(ref.s_W.x(), ref.s_W.y(), 0.02));
  ASSERT_TRUE(uv.has_value());
  const cv::Vec3b at_s = shot.at<cv::Vec3b>(static_cast<int>(std::lround(uv->y())),
                                            static_cast<int>(std::lround(uv->x())));
  EXPECT_GT(at_s[2], 150) << "BGR at s: " << at_s;
  EXPECT_LT(at_s[1], 80) << "BGR at s: " << at_s;
  const Comparison c = compare(shot, ref.frame);
  EXPECT_GT(c.pixels_beyond, 10000) << "of " << shot.total();
}

// --mjcf: the run is that of the user's scene. The unedited export of seed 1 gives the built
// scene's picture to the pixel; the tracer made ten times heavier (eq. (8)'s drag scales with the
// file's mass, the pressure push near s does not) is elsewhere at frame kSteps.
TEST_F(ViewCliTest, MjcfSceneIsTheOneShown) {
  const std::string d = scratch_dir("view_mjcf");
  ASSERT_EQ(run_airtwin("scene '" + line_file() + "' --seed 1 --air model --drag eq8 --out " + d)
                .exit_code,
            0);
  const std::string xml = testing::file_text(d + "/scene.xml");
  const std::string mass = "mass=\"0.00016000000000000001\"";
  ASSERT_NE(xml.find(mass), std::string::npos);
  std::string heavy = xml;
  heavy.replace(heavy.find(mass), mass.size(), "mass=\"0.0016000000000000001\"");
  { std::ofstream(d + "/heavy.xml", std::ios::binary) << heavy; }

  const cv::Mat built = screenshot("--no-overlay");
  const cv::Mat exported = screenshot("--no-overlay --mjcf " + d + "/scene.xml");
  const cv::Mat heavier = screenshot("--no-overlay --mjcf " + d + "/heavy.xml");
  ASSERT_FALSE(built.empty() || exported.empty() || heavier.empty());
  EXPECT_EQ(compare(built, exported).pixels_differing, 0);
  EXPECT_GT(compare(exported, heavier).pixels_differing, 0);
}

// The keys and the mouse, as a user's X events: xdotool (Debian's xdotool, scripts/setup.sh)
// sends them through the X server's XTest extension to the window of `airtwin view --paused`,
// and reads the state the window puts in its title. Each check waits for the title to change
// (polling, at most kPatience), never for a time.
constexpr double kPatience = 20.0;  // s; only reached when a test fails

// stdout of a shell command, without its trailing newline.
std::string shell_output(const std::string& command) {
  std::string out;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return out;
  char buffer[512];
  while (std::fgets(buffer, sizeof(buffer), pipe)) out += buffer;
  ::pclose(pipe);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

bool has_xdotool() { return shell_output("command -v xdotool") != ""; }

// `airtwin view <args>` in the background, its window driven by xdotool.
class LiveView {
 public:
  explicit LiveView(const std::string& args) : dir_(scratch_dir("view_input")) {
    const std::string command = std::string("'") + AIRTWIN_BINARY + "' view " + args +
                                " </dev/null >'" + dir_ + "/out' 2>'" + dir_ + "/err'";
    pid_ = ::fork();
    if (pid_ == 0) {
      ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    // The window, once mapped, and the pointer in its middle: keys go to the window under it.
    for (double waited = 0.0; waited < kPatience && window_.empty() && running(); waited += 0.05) {
      window_ = shell_output("xdotool search --onlyvisible --name '^airtwin view' 2>/dev/null");
      if (window_.empty()) ::usleep(50000);
    }
    if (!window_.empty()) {
      xdo("windowfocus --sync " + window_ + " mousemove --window " + window_ + " 512 512");
    }
  }
  ~LiveView() {
    if (pid_ > 0 && running()) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  bool has_window() const { return !window_.empty(); }
  void xdo(const std::string& args) const { shell_output("xdotool " + args); }
  std::string title() const { return shell_output("xdotool getwindowname " + window_); }
  // The title once `part` is in it (or the last title after kPatience).
  std::string title_with(const std::string& part) const {
    std::string t = title();
    for (double waited = 0.0; waited < kPatience && t.find(part) == std::string::npos;
         waited += 0.02) {
      ::usleep(20000);
      t = title();
    }
    return t;
  }
  // The title once it differs from `before`.
  std::string title_after(const std::string& before) const {
    std::string t = title();
    for (double waited = 0.0; waited < kPatience && t == before; waited += 0.02) {
      ::usleep(20000);
      t = title();
    }
    return t;
  }
  // Waits for `airtwin view` to end: its exit status (-1 if killed after kPatience).
  int wait() {
    int status = 0;
    for (double waited = 0.0; waited < kPatience; waited += 0.02) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      ::usleep(20000);
    }
    return -1;
  }
  std::string out() const { return testing::file_text(dir_ + "/out"); }
  std::string err() const { return testing::file_text(dir_ + "/err"); }
  const std::string& dir() const { return dir_; }

 private:
  bool running() const { return pid_ > 0 && ::waitpid(pid_, nullptr, WNOHANG) == 0; }
  std::string dir_;
  pid_t pid_ = -1;
  std::string window_;
};

// The simulated time in a title ("... | 0.075 s | ...").
double title_time(const std::string& title) {
  const size_t bar = title.find(" | ");
  return bar == std::string::npos ? -1.0 : std::atof(title.c_str() + bar + 3);
}

class ViewInputTest : public ViewCliTest {
 protected:
  void SetUp() override {
    if (!has_xdotool()) {
      GTEST_SKIP() << "xdotool is not installed (Debian's xdotool; scripts/setup.sh installs it)";
    }
    ViewCliTest::SetUp();
  }
  // The mirror twin (the model's air, eq. (8) drag): it needs no CFD cases read before the window
  // opens, and these tests are of the window, not of the physics.
  const std::string view_line_ =
      "'" + line_file() + "' --seed 1 --paused" + testing::mirror_flags();
};

// Paused, the run does not advance; each right arrow is one camera frame (25 ms), no more.
TEST_F(ViewInputTest, PausedRunStaysAndRightArrowStepsOneFrame) {
  LiveView view(view_line_ + "--speed 64");
  ASSERT_TRUE(view.has_window()) << view.err();
  const std::string start = view.title_with("| 0.000 s | paused");
  EXPECT_NE(start.find("| 0.000 s | paused | x64 | camera free | overlay on"), std::string::npos)
      << start;
  ::usleep(500000);  // at x64 an unpaused run would be 32 s on by now
  EXPECT_EQ(title_time(view.title()), 0.0) << view.title();
  std::string before = view.title();
  for (const double expected : {0.025, 0.050, 0.075}) {
    view.xdo("key Right");
    before = view.title_after(before);
    EXPECT_NEAR(title_time(before), expected, 1e-9) << before;
  }
  ::usleep(300000);
  EXPECT_NEAR(title_time(view.title()), 0.075, 1e-9) << "a step set the run going";
  view.xdo("key Escape");
  EXPECT_EQ(view.wait(), 0) << view.err();
  EXPECT_NE(view.out().find("window closed at t = 0.075 s (4 frames shown)"), std::string::npos)
      << view.out();
}

// Space runs the paused run and pauses it again; paused, its time stands still.
TEST_F(ViewInputTest, SpaceRunsAndPauses) {
  // x16: past 1 s within a tenth of a second, and the line's 120 s limit 7.5 s of wall time away,
  // far from any race with the second press.
  LiveView view(view_line_ + "--speed 16");
  ASSERT_TRUE(view.has_window()) << view.err();
  view.title_with("paused");
  view.xdo("key space");
  EXPECT_NE(view.title_with("running").find("running"), std::string::npos);
  std::string t = view.title();
  for (double waited = 0.0; waited < kPatience && title_time(t) < 1.0; waited += 0.02) {
    ::usleep(20000);
    t = view.title();
  }
  EXPECT_GE(title_time(t), 1.0) << t;
  view.xdo("key space");
  const std::string paused = view.title_with("paused");
  ASSERT_NE(paused.find("paused"), std::string::npos) << paused;
  ::usleep(500000);
  EXPECT_EQ(view.title(), paused);
  view.xdo("key Escape");
  EXPECT_EQ(view.wait(), 0) << view.err();
  char closed[64];
  std::snprintf(closed, sizeof(closed), "window closed at t = %.3f s", title_time(paused));
  EXPECT_NE(view.out().find(closed), std::string::npos) << view.out() << " vs " << paused;
}

// + and - double and halve the asked speed, within [1/64, 64].
TEST_F(ViewInputTest, PlusAndMinusSetTheSpeed) {
  LiveView view(view_line_ + "--speed 1");
  ASSERT_TRUE(view.has_window()) << view.err();
  const std::vector<std::pair<std::string, std::string>> steps = {
      {"plus", "| x2 |"},
      {"plus plus", "| x8 |"},
      {"minus", "| x4 |"},
      {"plus plus plus plus plus plus", "| x64 |"},  // 4 -> 64 in four, then held
      {"minus", "| x32 |"},
      {"minus minus minus minus minus minus minus minus minus minus minus", "| x0.015625 |"}};
  for (const auto& [keys, expected] : steps) {
    view.xdo("key " + keys);
    const std::string t = view.title_with(expected);
    EXPECT_NE(t.find(expected), std::string::npos) << keys << ": " << t;
  }
  EXPECT_NE(view.title().find("| 0.000 s | paused"), std::string::npos) << view.title();
  view.xdo("key Escape");
  EXPECT_EQ(view.wait(), 0) << view.err();
}

// C from the free camera gives the model's camera `top`, O hides the overlay: the screenshot of
// frame 1 is then the offscreen camera frame of that state (within the bounds above); with the
// overlay on, the same view differs from it by the air's arrows, the path and s. C again goes
// back to the free camera (the line's model has one camera).
TEST_F(ViewInputTest, CameraCycleAndOverlayKey) {
  const Reference ref = reference_frame(1);
  cv::Mat with_overlay;
  const std::string shot_path = scratch_dir("view_keys") + "/shot.png";
  for (const bool hide : {true, false}) {
    LiveView view(view_line_ + "--steps 1 --screenshot '" + shot_path + "'");
    ASSERT_TRUE(view.has_window()) << view.err();
    view.xdo("key c");
    EXPECT_NE(view.title_with("camera top").find("camera top | overlay on"), std::string::npos);
    if (hide) {
      view.xdo("key o");
      EXPECT_NE(view.title_with("overlay off").find("overlay off"), std::string::npos);
    }
    view.xdo("key Right");
    ASSERT_EQ(view.wait(), 0) << view.err();
    const cv::Mat shot = cv::imread(shot_path, cv::IMREAD_COLOR);
    ASSERT_FALSE(shot.empty());
    const Comparison c = compare(shot, ref.frame);
    if (hide) {
      EXPECT_LE(c.mean_abs_diff, 0.01);
      EXPECT_LE(c.pixels_beyond, kAllowedBeyond);
    } else {
      EXPECT_GT(c.pixels_beyond, 10000) << "the overlay is missing";
      with_overlay = shot;
    }
  }
  LiveView view(view_line_);
  ASSERT_TRUE(view.has_window());
  view.xdo("key c");
  view.title_with("camera top");
  view.xdo("key c");
  EXPECT_NE(view.title_with("camera free").find("camera free"), std::string::npos);
  view.xdo("key Escape");
  EXPECT_EQ(view.wait(), 0);
}

// The small bright blobs of a screenshot without the overlay (px): the tracer, and white parts
// of the rig.
std::vector<cv::Point2d> bright_blobs(const cv::Mat& shot) {
  cv::Mat grey, bright, labels, stats, centroids;
  cv::cvtColor(shot, grey, cv::COLOR_BGR2GRAY);
  cv::threshold(grey, bright, 200, 255, cv::THRESH_BINARY);
  const int n = cv::connectedComponentsWithStats(bright, labels, stats, centroids);
  std::vector<cv::Point2d> blobs;
  for (int i = 1; i < n; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) > 2000) continue;
    blobs.emplace_back(centroids.at<double>(i, 0), centroids.at<double>(i, 1));
  }
  return blobs;
}

// Distance (px) from `p` to the nearest blob.
double nearest_blob(const cv::Mat& shot, const cv::Point2d& p) {
  double best = 1e9;
  for (const cv::Point2d& b : bright_blobs(shot)) best = std::min(best, cv::norm(b - p));
  return best;
}

// The blob on the ray from `centre` through `p` (within 2 degrees), farther than 30 px from the
// centre: its distance from the centre, or -1.
double radius_on_ray(const cv::Mat& shot, const cv::Point2d& centre, const cv::Point2d& p) {
  const double angle = std::atan2(p.y - centre.y, p.x - centre.x);
  for (const cv::Point2d& b : bright_blobs(shot)) {
    const cv::Point2d d = b - centre;
    const double off = std::remainder(std::atan2(d.y, d.x) - angle, 2.0 * M_PI);
    if (cv::norm(d) > 30.0 && std::fabs(off) < 2.0 * M_PI / 180.0) return cv::norm(d);
  }
  return -1.0;
}

// The mouse, from the top camera at frame 1 without the overlay, each drag's motion events sent
// at once (as a quick hand queues them). Any drag or the wheel takes the free camera over
// (title). The tracer starts at (-0.26, 0.25) m, 2.64 mm/px: (413, 417) px in the top camera
// (checked). A right drag moves the floor the camera looks at with the pointer: the tracer moves
// by the drag's 200 px. A left drag turns the view about the vertical through the centre by
// MuJoCo's 180 degrees per window height of drag (200 / 1024 x 180 = 35.2 degrees; mjv_moveCamera):
// the tracer goes round the centre by that angle. The wheel towards the user zooms in (the tracer
// farther out on its ray from the centre), away zooms out.
TEST_F(ViewInputTest, MouseDragsAndWheelMoveTheCamera) {
  const std::string shot_path = scratch_dir("view_mouse") + "/shot.png";
  auto shot_after = [&](const std::string& mouse) {
    LiveView view(view_line_ + "--camera top --no-overlay --steps 1 --screenshot '" + shot_path +
                  "'");
    EXPECT_TRUE(view.has_window()) << view.err();
    if (!view.has_window()) return cv::Mat();
    EXPECT_NE(view.title_with("camera top").find("camera top"), std::string::npos);
    if (!mouse.empty()) {
      view.xdo(mouse);
      EXPECT_NE(view.title_with("camera free").find("camera free"), std::string::npos) << mouse;
    }
    view.xdo("key Right");
    EXPECT_EQ(view.wait(), 0) << view.err();
    return cv::imread(shot_path, cv::IMREAD_COLOR);
  };
  const cv::Point2d centre(512, 512), tracer(413, 417);
  const cv::Mat top = shot_after("");
  ASSERT_FALSE(top.empty());
  EXPECT_LT(nearest_blob(top, tracer), 3.0);

  const cv::Mat moved =
      shot_after("mousedown 3 mousemove_relative 100 0 mousemove_relative 100 0 mouseup 3");
  EXPECT_LT(nearest_blob(moved, tracer + cv::Point2d(200, 0)), 8.0);
  EXPECT_GT(nearest_blob(moved, tracer), 100.0) << "the floor did not move";

  const cv::Mat turned =
      shot_after("mousedown 1 mousemove_relative 100 0 mousemove_relative 100 0 mouseup 1");
  const double turn = -200.0 / 1024.0 * M_PI;  // image y points down: the turn is clockwise here
  const cv::Point2d r = tracer - centre;
  const cv::Point2d expected(centre.x + r.x * std::cos(turn) - r.y * std::sin(turn),
                             centre.y + r.x * std::sin(turn) + r.y * std::cos(turn));
  EXPECT_LT(nearest_blob(turned, expected), 8.0) << expected;
  EXPECT_GT(nearest_blob(turned, tracer), 40.0) << "the view did not turn";

  const double r_top = cv::norm(r);
  const double r_in = radius_on_ray(shot_after("click --repeat 2 5"), centre, tracer);
  const double r_out = radius_on_ray(shot_after("click --repeat 2 4"), centre, tracer);
  std::printf("tracer %.1f px from the centre, %.1f after the wheel towards, %.1f away\n", r_top,
              r_in, r_out);
  EXPECT_GT(r_in, 1.2 * r_top);
  EXPECT_GT(r_out, 0.0);
  EXPECT_LT(r_out, 0.9 * r_top);
}

// Bad input: one line on stderr, a non-zero exit, quickly; no window is needed to say so.
TEST(ViewCliErrors, MissingScenarioIsOneLine) {
  const testing::CliResult r = run_airtwin("view /nonexistent/scenario.yaml --seed 1");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("/nonexistent/scenario.yaml"), std::string::npos) << r.err;
}

TEST(ViewCliErrors, NoDisplayIsOneLine) {
  ::unsetenv("DISPLAY");
  const testing::CliResult r = run_airtwin("view '" + line_file() + "' --seed 1");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("DISPLAY is not set"), std::string::npos) << r.err;
}

TEST(ViewCliErrors, DisplayWithoutServerIsOneLine) {
  // A display number no server listens on: the window process cannot open, and says why.
  ::setenv("DISPLAY", ":9917", 1);
  const testing::CliResult r = run_airtwin("view '" + line_file() + "' --seed 1");
  ::unsetenv("DISPLAY");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("cannot open a window"), std::string::npos) << r.err;
}

TEST(ViewCliErrors, BadFlagsAreUsageErrors) {
  ::setenv("DISPLAY", ":9917", 1);
  const testing::CliResult speed = run_airtwin("view '" + line_file() + "' --speed 0");
  const testing::CliResult shot = run_airtwin("view '" + line_file() + "' --screenshot x.png");
  ::unsetenv("DISPLAY");
  EXPECT_EQ(speed.exit_code, 2);
  EXPECT_EQ(count_lines(speed.err), 1) << speed.err;
  EXPECT_NE(speed.err.find("--speed"), std::string::npos) << speed.err;
  EXPECT_EQ(shot.exit_code, 2);
  EXPECT_NE(shot.err.find("--steps"), std::string::npos) << shot.err;
}

}  // namespace
}  // namespace airtwin
