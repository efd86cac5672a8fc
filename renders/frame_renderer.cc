#include "renders/frame_renderer.h"

#include <opencv2/imgproc.hpp>

#include "common/errors.h"
#include "renders/offscreen_context.h"
#include "renders/sensor_effects.h"
#include "sim/kinematic_state.h"
#include "sim/mujoco_runtime.h"
#include "sim/scene_look.h"

namespace airtwin {
namespace {

// Room in the scene for the model's geoms plus MuJoCo's decorations (none are enabled).
constexpr int kExtraSceneGeoms = 100;

}  // namespace

struct FrameRenderer::Impl {
  const mjModel* m = nullptr;
  RenderOptions options;
  std::unique_ptr<OffscreenContext> context;
  DataPtr mirror;  // the renderer's copy of the state's kinematics
  mjvScene scene;
  mjvOption option;
  mjvCamera camera;
  mjvPerturb perturb;
  bool scene_made = false;
  cv::Mat rgb_bottom_up;  // MuJoCo's read-back: RGB, first row = bottom of the picture
  cv::Mat rgb;            // the same, rows top-down

  ~Impl() {
    // The scene is plain memory; no GL context is needed to free it.
    if (scene_made) mjv_freeScene(&scene);
  }
};

FrameRenderer::FrameRenderer(const mjModel* m, const RenderOptions& options,
                             const std::string& camera)
    : impl_(std::make_unique<Impl>()) {
  AIRTWIN_DEMAND(m != nullptr);
  install_mujoco_handlers();
  Impl& s = *impl_;
  s.m = m;
  s.options = options;
  // Options and camera: user input, checked before any GL work.
  validate_sensor_effects(options.noise_sigma_grey, options.blur_sigma_px);
  const int camera_id = mj_name2id(m, mjOBJ_CAMERA, camera.c_str());
  if (camera_id < 0) throw InputError("model: no camera named '" + camera + "' to render");

  s.context = std::make_unique<OffscreenContext>(m, options.multisamples);
  s.mirror = make_data(m);

  // The abstract scene: this renderer's own, sized for every geom of the model.
  mjv_defaultScene(&s.scene);
  mjv_makeScene(m, &s.scene, m->ngeom + kExtraSceneGeoms);
  s.scene_made = true;
  // The look shared with the live viewer (sim/scene_look.h).
  mjv_defaultOption(&s.option);
  apply_scene_look(&s.option, &s.scene);
  // The model's fixed camera; no perturbation.
  mjv_defaultCamera(&s.camera);
  s.camera.type = mjCAMERA_FIXED;
  s.camera.fixedcamid = camera_id;
  mjv_defaultPerturb(&s.perturb);

  s.rgb_bottom_up.create(s.context->height_px(), s.context->width_px(), CV_8UC3);
}

FrameRenderer::~FrameRenderer() = default;
FrameRenderer::FrameRenderer(FrameRenderer&&) noexcept = default;
FrameRenderer& FrameRenderer::operator=(FrameRenderer&&) noexcept = default;

cv::Mat FrameRenderer::render(const mjData* d, int64_t frame_index) {
  cv::Mat bgr;
  render_into(d, frame_index, bgr);
  return bgr;
}

void FrameRenderer::render_into(const mjData* d, int64_t frame_index, cv::Mat& bgr) {
  AIRTWIN_DEMAND(d != nullptr);
  Impl& s = *impl_;
  // The scene from the renderer's mirror of the state, so that MuJoCo writes nothing into `d`.
  mirror_kinematics(s.m, d, s.mirror.get());
  mjv_updateScene(s.m, s.mirror.get(), &s.option, &s.perturb, &s.camera, mjCAT_ALL, &s.scene);
  // Draw and read back on this thread's context (OpenGL's rows run bottom-up), while no other
  // thread is creating a context.
  {
    const auto hold = s.context->gl_use();
    s.context->make_current();
    const mjrRect viewport{0, 0, s.context->width_px(), s.context->height_px()};
    mjr_render(viewport, &s.scene, s.context->mjr());
    mjr_readPixels(s.rgb_bottom_up.data, nullptr, viewport, s.context->mjr());
  }
  // To a camera's image: rows top-down, BGR.
  cv::flip(s.rgb_bottom_up, s.rgb, 0);
  cv::cvtColor(s.rgb, bgr, cv::COLOR_RGB2BGR);
  // Optics and sensor.
  apply_sensor_effects(bgr, s.options.noise_sigma_grey, s.options.blur_sigma_px, s.options.seed,
                       frame_index);
}

int FrameRenderer::width_px() const { return impl_->context->width_px(); }
int FrameRenderer::height_px() const { return impl_->context->height_px(); }
const RenderOptions& FrameRenderer::options() const { return impl_->options; }
const std::string& FrameRenderer::gl_renderer() const { return impl_->context->gl_renderer(); }

}  // namespace airtwin
