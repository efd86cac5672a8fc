#include "viewer/viewer_window.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include <mujoco/mujoco.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/errors.h"
#include "sim/kinematic_state.h"
#include "sim/mujoco_runtime.h"
#include "sim/scene_look.h"
#include "viewer/view_frame.h"
#include "viewer/viewer_channel.h"

namespace airtwin {
namespace {

constexpr double kCameraRateHz = 40.0;  // the twin's camera: one frame is 25 ms of simulated time
constexpr double kMinSpeed = 1.0 / 64.0, kMaxSpeed = 64.0;
constexpr double kDrawPeriodS = 1.0 / 60.0;  // frames fetched between two draws: at most this long
constexpr int kOverlayGeoms = 3000;          // room in the scene beyond the model's geoms
// The overlay's sizes (m) and the arrows' scale: an arrow is the distance the air travels in
// kArrowSeconds (4 m/s: 20 cm, about the grid's spacing); slower air than kArrowMinSpeed is
// not drawn.
constexpr double kArrowSeconds = 0.05, kArrowMinSpeed = 0.2, kArrowWidth = 0.008;
constexpr double kArrowTopSpeed = 4.0;  // red at and above this speed (m/s)
// The overlay glows a little, so that its colours read the same from every side of the lights.
constexpr float kOverlayEmission = 0.5f;

// The last GLFW error (GLFW reports through a callback).
std::string& glfw_error() {
  static std::string error;
  return error;
}

// Blue (slow) -> green -> yellow -> red (fast): the air speed `v` (m/s) as a colour.
void speed_colour(double v, float rgba[4]) {
  const double t = std::clamp(v / kArrowTopSpeed, 0.0, 1.0);
  rgba[0] = static_cast<float>(std::clamp(2.0 * t, 0.0, 1.0));
  rgba[1] = static_cast<float>(t < 0.5 ? 2.0 * t : 2.0 - 2.0 * t) * 0.9f + 0.1f;
  rgba[2] = static_cast<float>(std::clamp(1.0 - 2.0 * t, 0.0, 1.0));
  rgba[3] = 1.0f;
}

class Window {
 public:
  Window(int fd, const ViewerWindowOptions& options) : fd_(fd), options_(options) {}
  ~Window();
  void run();

 private:
  // Opening: the window and its GL context, then the model and the first frame.
  void open_window();
  void receive_model();
  // One more camera frame from the simulation (false: the run is over or the simulation gone).
  bool advance();
  void draw(bool screenshot);
  void add_overlay();
  void add_geom(int type, const float rgba[4], const mjtNum size[3], const mjtNum pos[3]);
  void add_connector(int type, double width, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                     const float rgba[4]);
  void write_screenshot(const mjrRect& viewport);
  void show_state_in_title();
  void reanchor();
  double sim_time() const { return data_ ? data_->time : 0.0; }
  // The options' steps are done: that many camera frames shown past the first.
  bool steps_done() const {
    return options_.steps > 0 && frame_.index - first_index_ >= options_.steps;
  }
  void use_free_camera(bool from_above);
  void take_free_camera();

  // GLFW's callbacks, forwarded to the Window of the GLFW window.
  static Window& of(GLFWwindow* w) { return *static_cast<Window*>(glfwGetWindowUserPointer(w)); }
  void on_key(int key, int action, int mods);
  void on_button(int button, int action);
  void on_move(double x, double y);
  void on_scroll(double dy);

  int fd_;
  ViewerWindowOptions options_;
  GLFWwindow* window_ = nullptr;
  bool glfw_ready_ = false;
  ModelPtr model_;
  DataPtr data_;
  mjvScene scene_;
  mjvCamera camera_;
  mjvOption option_;
  mjvPerturb perturb_;
  mjrContext context_;
  bool scene_made_ = false, context_made_ = false;

  ViewFrame frame_;  // the frame shown (its kinematics are in data_)
  int64_t first_index_ = -1;
  bool ended_ = false, simulation_gone_ = false;
  std::string verdict_;

  bool paused_ = false;
  int step_requests_ = 0;
  double speed_ = 1.0;
  double anchor_wall_ = 0.0, anchor_sim_ = 0.0;    // pacing: sim time due = anchor + speed x wall
  std::deque<std::pair<double, double>> history_;  // (wall, sim) of the last 2 s: the speed
  bool overlay_ = true;

  bool left_ = false, middle_ = false, right_ = false;
  double last_x_ = 0.0, last_y_ = 0.0;
  bool cursor_seen_ = false;  // last_x_, last_y_ come from a cursor event
  std::string title_;         // the title shown (set again only when the state changes)
};

Window::~Window() {
  if (context_made_) mjr_freeContext(&context_);
  if (scene_made_) mjv_freeScene(&scene_);
  if (window_) glfwDestroyWindow(window_);
  if (glfw_ready_) glfwTerminate();
}

void Window::open_window() {
  glfwSetErrorCallback([](int, const char* text) { glfw_error() = text ? text : ""; });
  if (!glfwInit()) {
    throw ViewerError("cannot open a window: " +
                      (glfw_error().empty() ? "GLFW failed to start" : glfw_error()));
  }
  glfw_ready_ = true;
  // The camera frames are not multisampled either (docs/rendering.md): the same picture.
  glfwWindowHint(GLFW_SAMPLES, 0);
  glfwWindowHint(GLFW_DOUBLEBUFFER, GLFW_TRUE);
  window_ = glfwCreateWindow(options_.width_px, options_.height_px, options_.title.c_str(), nullptr,
                             nullptr);
  if (!window_) {
    throw ViewerError("cannot open an OpenGL window: " +
                      (glfw_error().empty() ? "GLFW failed" : glfw_error()));
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(1);
  glfwSetWindowUserPointer(window_, this);
  glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int, int action, int mods) {
    of(w).on_key(key, action, mods);
  });
  glfwSetMouseButtonCallback(
      window_, [](GLFWwindow* w, int button, int action, int) { of(w).on_button(button, action); });
  glfwSetCursorPosCallback(window_, [](GLFWwindow* w, double x, double y) { of(w).on_move(x, y); });
  glfwSetScrollCallback(window_, [](GLFWwindow* w, double, double dy) { of(w).on_scroll(dy); });
}

void Window::receive_model() {
  const std::optional<ViewMessage> message = receive_view_message(fd_);
  if (!message) throw ViewerError("the simulation went away before sending the model");
  if (message->type != ViewMessageType::kModel) {
    throw ViewerError("viewer connection: expected the model first");
  }
  model_ = model_from_bytes(message->payload);
  data_ = make_data(model_.get());
  const mjModel* m = model_.get();
  // MuJoCo's scene, options and rendering context, on this window's GL context.
  mjv_defaultScene(&scene_);
  mjv_makeScene(m, &scene_, m->ngeom + kOverlayGeoms);
  scene_made_ = true;
  mjv_defaultOption(&option_);
  apply_scene_look(&option_, &scene_);
  mjv_defaultPerturb(&perturb_);
  mjr_defaultContext(&context_);
  mjr_makeContext(m, &context_, mjFONTSCALE_150);
  context_made_ = true;
  mjr_setBuffer(mjFB_WINDOW, &context_);
  // The camera: a fixed one of the model, or the free one.
  mjv_defaultCamera(&camera_);
  if (options_.camera.empty()) {
    use_free_camera(false);
  } else {
    const int id = mj_name2id(m, mjOBJ_CAMERA, options_.camera.c_str());
    if (id < 0) throw InputError("viewer: the model has no camera named '" + options_.camera + "'");
    camera_.type = mjCAMERA_FIXED;
    camera_.fixedcamid = id;
  }
}

void Window::use_free_camera(bool from_above) {
  // Looking at the floor around the point below the nozzle: straight down (image up = +y, as
  // the top camera) or obliquely from the -y side.
  camera_.type = mjCAMERA_FREE;
  camera_.fixedcamid = -1;
  camera_.lookat[0] = 0.0;
  camera_.lookat[1] = 0.0;
  camera_.lookat[2] = 0.0;
  camera_.distance = from_above ? 3.2 : 3.4;
  camera_.azimuth = 90.0;
  camera_.elevation = from_above ? -89.9 : -50.0;
}

void Window::take_free_camera() {
  // A fixed camera cannot move: take the free camera over from straight above. mjv_moveCamera
  // moves a camera in the frame of the scene's camera, which is the fixed one until the next
  // draw: set it to the free camera now, so that the events already queued move the free one.
  use_free_camera(true);
  mjv_updateCamera(model_.get(), data_.get(), &camera_, &scene_);
}

bool Window::advance() {
  if (ended_ || simulation_gone_) return false;
  send_view_message(fd_, ViewMessageType::kNext);
  const std::optional<ViewMessage> message = receive_view_message(fd_);
  if (!message) {
    simulation_gone_ = true;
    return false;
  }
  if (message->type == ViewMessageType::kEnd) {
    ended_ = true;
    verdict_ = message->payload;
    return false;
  }
  if (message->type != ViewMessageType::kFrame) {
    throw ViewerError("viewer connection: expected a frame");
  }
  frame_ = decode_view_frame(message->payload);
  restore_kinematics(model_.get(), frame_.kinematics, data_.get());
  if (first_index_ < 0) first_index_ = frame_.index;
  return true;
}

void Window::reanchor() {
  anchor_wall_ = glfwGetTime();
  anchor_sim_ = sim_time();
  history_.clear();
}

void Window::add_geom(int type, const float rgba[4], const mjtNum size[3], const mjtNum pos[3]) {
  if (scene_.ngeom >= scene_.maxgeom) return;
  mjvGeom* g = scene_.geoms + scene_.ngeom++;
  mjv_initGeom(g, type, size, pos, nullptr, rgba);
  g->category = mjCAT_DECOR;
  g->emission = kOverlayEmission;
}

void Window::add_connector(int type, double width, const Eigen::Vector3d& a,
                           const Eigen::Vector3d& b, const float rgba[4]) {
  if (scene_.ngeom >= scene_.maxgeom) return;
  mjvGeom* g = scene_.geoms + scene_.ngeom++;
  mjv_initGeom(g, type, nullptr, nullptr, nullptr, rgba);
  mjv_makeConnector(g, type, width, a.x(), a.y(), a.z(), b.x(), b.y(), b.z());
  g->category = mjCAT_DECOR;
  g->emission = kOverlayEmission;
}

void Window::add_overlay() {
  const ViewOverlay& o = frame_.overlay;
  auto at = [](const Eigen::Vector2d& p, double z) { return Eigen::Vector3d(p.x(), p.y(), z); };
  // The air on the floor: arrows along the mean air, coloured by its speed.
  for (const ViewArrow& a : o.air) {
    const double speed = a.v_W.norm();
    if (speed < kArrowMinSpeed) continue;
    float rgba[4];
    speed_colour(speed, rgba);
    add_connector(mjGEOM_ARROW, kArrowWidth, at(a.p_W, 0.01),
                  at(a.p_W + kArrowSeconds * a.v_W, 0.01), rgba);
  }
  // The zones: translucent discs on the floor.
  for (const ViewZone& z : o.zones) {
    const float rgba[4] = {1.0f, 0.85f, 0.2f, 0.3f};
    const mjtNum size[3] = {z.radius_m, 0.001, 0.0};  // a geom's (radius, half-height)
    const mjtNum pos[3] = {z.centre_W.x(), z.centre_W.y(), 0.001};
    add_geom(mjGEOM_CYLINDER, rgba, size, pos);
    if (scene_.ngeom > 0 && !z.label.empty()) {
      std::snprintf(scene_.geoms[scene_.ngeom - 1].label, sizeof(scene_.geoms[0].label), "%s",
                    z.label.c_str());
    }
  }
  // The path (green) and its reference points.
  const float green[4] = {0.2f, 0.85f, 0.25f, 1.0f};
  for (size_t k = 1; k < o.path_W.size(); ++k) {
    add_connector(mjGEOM_CAPSULE, 0.004, at(o.path_W[k - 1], 0.004), at(o.path_W[k], 0.004), green);
  }
  for (const Eigen::Vector2d& r : o.path_references_W) {
    const mjtNum size[3] = {0.008, 0.008, 0.008};
    const mjtNum pos[3] = {r.x(), r.y(), 0.004};
    add_geom(mjGEOM_SPHERE, green, size, pos);
  }
  // The references being steered to (magenta) and the stagnation point s (red, with a post).
  for (const Eigen::Vector2d& r : o.current_references_W) {
    // A translucent disc on the floor, so that the object reaching it stays visible.
    const float magenta[4] = {0.9f, 0.2f, 0.9f, 0.6f};
    const mjtNum size[3] = {0.025, 0.0015, 0.0};  // a geom's (radius, half-height)
    const mjtNum pos[3] = {r.x(), r.y(), 0.0015};
    add_geom(mjGEOM_CYLINDER, magenta, size, pos);
  }
  if (o.stagnation_W) {
    const float red[4] = {0.95f, 0.1f, 0.1f, 1.0f};
    const mjtNum size[3] = {0.02, 0.02, 0.02};
    const mjtNum pos[3] = {o.stagnation_W->x(), o.stagnation_W->y(), 0.02};
    add_geom(mjGEOM_SPHERE, red, size, pos);
    add_connector(mjGEOM_CAPSULE, 0.004, at(*o.stagnation_W, 0.0), at(*o.stagnation_W, 0.25), red);
  }
}

void Window::draw(bool screenshot) {
  int width = 0, height = 0;
  glfwGetFramebufferSize(window_, &width, &height);
  const mjrRect viewport{0, 0, width, height};
  mjv_updateScene(model_.get(), data_.get(), &option_, &perturb_, &camera_, mjCAT_ALL, &scene_);
  if (overlay_) add_overlay();
  mjr_render(viewport, &scene_, &context_);
  if (screenshot) write_screenshot(viewport);

  // The text: time, frame, speed and state at the top left; the caption at the top right; the
  // keys at the bottom left.
  char values[256];
  double measured = 0.0;
  if (history_.size() >= 2 && history_.back().first > history_.front().first) {
    measured = (history_.back().second - history_.front().second) /
               (history_.back().first - history_.front().first);
  }
  const char* state = ended_ ? "run over" : paused_ ? "paused" : "running";
  std::snprintf(values, sizeof(values), "%.3f s\n%lld\nx%g asked, x%.2f real\n%s", sim_time(),
                static_cast<long long>(frame_.index), speed_, paused_ || ended_ ? 0.0 : measured,
                state);
  mjr_overlay(mjFONT_NORMAL, mjGRID_TOPLEFT, viewport, "Time\nFrame\nSpeed\nState", values,
              &context_);
  std::string caption = frame_.overlay.caption;
  if (ended_) caption += "\n" + verdict_;
  mjr_overlay(mjFONT_NORMAL, mjGRID_TOPRIGHT, viewport, caption.c_str(), nullptr, &context_);
  mjr_overlay(mjFONT_NORMAL, mjGRID_BOTTOMLEFT, viewport, "Space\nRight\n+ / -\nMouse\nC\nO\nEsc",
              "pause\nstep (paused)\nspeed x2 / x0.5\nrotate, move, zoom\ncamera\noverlay\nquit",
              &context_);
  glfwSwapBuffers(window_);
  show_state_in_title();
}

void Window::write_screenshot(const mjrRect& viewport) {
  cv::Mat rgb_bottom_up(viewport.height, viewport.width, CV_8UC3);
  mjr_readPixels(rgb_bottom_up.data, nullptr, viewport, &context_);
  cv::Mat rgb, bgr;
  cv::flip(rgb_bottom_up, rgb, 0);
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  bool written = false;
  try {
    written = cv::imwrite(options_.screenshot, bgr, {cv::IMWRITE_PNG_COMPRESSION, 1});
  } catch (const cv::Exception&) {
    written = false;
  }
  if (!written) throw InputError(options_.screenshot + ": cannot write the screenshot");
}

void Window::show_state_in_title() {
  const mjModel* m = model_.get();
  const char* camera = camera_.type != mjCAMERA_FIXED ? "free"
                       : m && mj_id2name(m, mjOBJ_CAMERA, camera_.fixedcamid)
                           ? mj_id2name(m, mjOBJ_CAMERA, camera_.fixedcamid)
                           : "fixed";
  char state[256];
  std::snprintf(state, sizeof(state), " | %.3f s | %s | x%g | camera %s | overlay %s", sim_time(),
                ended_    ? "run over"
                : paused_ ? "paused"
                          : "running",
                speed_, camera, overlay_ ? "on" : "off");
  const std::string title = options_.title + state;
  if (title == title_) return;
  title_ = title;
  glfwSetWindowTitle(window_, title_.c_str());
}

void Window::on_key(int key, int action, int mods) {
  (void)mods;
  if (action == GLFW_RELEASE) return;
  switch (key) {
    case GLFW_KEY_ESCAPE:
      glfwSetWindowShouldClose(window_, GLFW_TRUE);
      break;
    case GLFW_KEY_SPACE:
      if (action == GLFW_PRESS) {
        paused_ = !paused_;
        reanchor();
      }
      break;
    case GLFW_KEY_RIGHT:
      if (paused_) ++step_requests_;
      break;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD:
      speed_ = std::min(kMaxSpeed, 2.0 * speed_);
      reanchor();
      break;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT:
      speed_ = std::max(kMinSpeed, 0.5 * speed_);
      reanchor();
      break;
    case GLFW_KEY_C:
      // Free -> each fixed camera of the model -> free.
      if (action != GLFW_PRESS) break;
      if (camera_.type == mjCAMERA_FIXED && camera_.fixedcamid + 1 < model_->ncam) {
        ++camera_.fixedcamid;
      } else if (camera_.type == mjCAMERA_FIXED || model_->ncam == 0) {
        use_free_camera(false);
      } else {
        camera_.type = mjCAMERA_FIXED;
        camera_.fixedcamid = 0;
      }
      break;
    case GLFW_KEY_O:
      if (action == GLFW_PRESS) overlay_ = !overlay_;
      break;
    default:
      break;
  }
}

void Window::on_button(int button, int action) {
  const bool down = action == GLFW_PRESS;
  if (button == GLFW_MOUSE_BUTTON_LEFT) left_ = down;
  if (button == GLFW_MOUSE_BUTTON_MIDDLE) middle_ = down;
  if (button == GLFW_MOUSE_BUTTON_RIGHT) right_ = down;
  // A drag starts where the last cursor event left the pointer. Asking the server now instead
  // would give where the pointer is after the motion still queued behind this press, and a quick
  // drag whose events arrive together would cancel out.
  if (!cursor_seen_) glfwGetCursorPos(window_, &last_x_, &last_y_);
}

void Window::on_move(double x, double y) {
  const double dx = x - last_x_, dy = y - last_y_;
  last_x_ = x;
  last_y_ = y;
  cursor_seen_ = true;
  if (!left_ && !middle_ && !right_) return;
  if (camera_.type != mjCAMERA_FREE) take_free_camera();
  const bool shift = glfwGetKey(window_, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                     glfwGetKey(window_, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
  int action = mjMOUSE_ZOOM;
  if (right_) {
    action = shift ? mjMOUSE_MOVE_H : mjMOUSE_MOVE_V;
  } else if (left_) {
    action = shift ? mjMOUSE_ROTATE_H : mjMOUSE_ROTATE_V;
  }
  int width = 0, height = 0;
  glfwGetWindowSize(window_, &width, &height);
  if (height <= 0) return;
  mjv_moveCamera(model_.get(), action, dx / height, dy / height, &scene_, &camera_);
}

void Window::on_scroll(double dy) {
  if (camera_.type != mjCAMERA_FREE) take_free_camera();
  mjv_moveCamera(model_.get(), mjMOUSE_ZOOM, 0.0, -0.05 * dy, &scene_, &camera_);
}

void Window::run() {
  speed_ = options_.speed;
  overlay_ = options_.overlay;
  paused_ = options_.paused;
  open_window();
  send_view_message(fd_, ViewMessageType::kReady);
  receive_model();
  if (!advance()) return;  // the run ended (or the simulation went away) before its first frame
  reanchor();
  while (!glfwWindowShouldClose(window_) && !simulation_gone_) {
    glfwPollEvents();
    const double start = glfwGetTime();
    // Fetch the frames the pacing asks for: one per step request while paused, otherwise those
    // due by now at the asked speed, for at most one draw period.
    if (paused_) {
      for (; step_requests_ > 0 && !steps_done(); --step_requests_) advance();
    } else if (!ended_) {
      const double due = anchor_sim_ + (start - anchor_wall_) * speed_;
      while (sim_time() + 0.5 / kCameraRateHz < due && glfwGetTime() - start < kDrawPeriodS &&
             !steps_done() && advance()) {
      }
      // More than 0.25 s behind (the simulation or the drawing cannot keep up): drop the debt
      // rather than race to catch up later.
      if (due - sim_time() > 0.25 * speed_) {
        anchor_wall_ = glfwGetTime();
        anchor_sim_ = sim_time();
      }
    }
    // The measured speed: simulated over wall time across the last 2 s, sampled once a loop
    // after the fetch (sampled per frame, the bursts after a slow draw biased it by ~10 %).
    if (!paused_ && !ended_) {
      history_.emplace_back(glfwGetTime(), sim_time());
      while (history_.size() > 2 && history_.back().first - history_.front().first > 2.0) {
        history_.pop_front();
      }
    }
    const bool done = options_.steps > 0 && (ended_ || steps_done());
    draw(done && !options_.screenshot.empty());
    if (done) break;
    // Idle while nothing is due: paused, over, or ahead of the asked speed.
    if (paused_ || ended_) {
      glfwWaitEventsTimeout(0.05);
    } else {
      const double due = anchor_sim_ + (glfwGetTime() - anchor_wall_) * speed_;
      const double wait_s = (sim_time() + 0.5 / kCameraRateHz - due) / speed_;
      if (wait_s > 0.0) glfwWaitEventsTimeout(std::min(wait_s, kDrawPeriodS));
    }
  }
  if (!simulation_gone_) send_view_message(fd_, ViewMessageType::kQuit);
}

}  // namespace

void run_viewer_window(int fd, const ViewerWindowOptions& options) {
  if (!(options.speed >= kMinSpeed && options.speed <= kMaxSpeed)) {
    throw FieldError("viewer.speed", "must be in [1/64, 64], got " + std::to_string(options.speed));
  }
  if (options.width_px < 16 || options.height_px < 16) {
    throw FieldError("viewer.size", "must be at least 16 x 16 px");
  }
  if (options.steps < 0) throw FieldError("viewer.steps", "must be >= 0");
  if (!options.screenshot.empty() && options.steps == 0) {
    throw FieldError("viewer.screenshot", "needs viewer.steps > 0");
  }
  install_mujoco_handlers();
  Window window(fd, options);
  try {
    window.run();
  } catch (const std::exception& e) {
    // Tell the simulation why (it prints the one line); it may be gone already.
    try {
      send_view_message(fd, ViewMessageType::kError, e.what());
    } catch (const ViewerError&) {
    }
    throw;
  }
}

}  // namespace airtwin
