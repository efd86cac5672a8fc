#pragma once
// The twin's top-view camera: one frame of a fixed camera of the model (normally `top`) rendered
// offscreen by MuJoCo's renderer into an OSMesa context (renders/offscreen_context.h), read back
// and returned as the 8-bit BGR image a camera driver would give: rows top-down, OpenCV's channel
// order, the model's offscreen size (1024 x 1024 px for the twin).
//
// The look (docs/rendering.md): the scene's textured floor, white tracers and cotton skins, its
// directional light and headlight; no shadows, reflections, skybox, fog or haze; visual geoms only
// (the colliders of group 3 and the sites stay hidden). Offscreen multisampling is off unless
// asked for: at 1024 x 1024 on llvmpipe the multisample resolve costs more than the rest of the
// frame. Optional blur and sensor noise (renders/sensor_effects.h) are applied after read-back.
//
// Rendering reads the twin's state and never writes it: the kinematic fields the scene is built
// from (body, geom, site, camera and light poses, tendon paths) are mirrored into the renderer's
// own mjData, and the renderer owns its mjvScene, mjvOption, mjvCamera and mjvPerturb. It shows
// the poses mjData holds, i.e. those Twin::object_state reports.
//
// One FrameRenderer per thread (it owns an OffscreenContext, which is bound to the calling thread
// before each frame). Same state, options and frame index -> same bytes.

#include <cstdint>
#include <memory>
#include <string>

#include <mujoco/mujoco.h>
#include <opencv2/core.hpp>

namespace airtwin {

struct RenderOptions {
  /// Offscreen multisamples per pixel (0 = off; 4 smooths edges at ~5-10x the cost).
  int multisamples = 0;
  /// Standard deviation of the per-pixel, per-channel Gaussian sensor noise (grey levels, 0-255).
  double noise_sigma_grey = 0.0;
  /// Standard deviation of the Gaussian blur (px).
  double blur_sigma_px = 0.0;
  /// Seed of the noise; with the frame index it fixes every noise value.
  uint64_t seed = 0;
};

class FrameRenderer {
 public:
  /// A renderer of camera `camera` of `m`, which must outlive it and stay unchanged. Creates the
  /// offscreen context on the calling thread. Throws InputError for an unknown camera, bad options
  /// or a model without an offscreen size, RenderError when OSMesa or GL fail.
  explicit FrameRenderer(const mjModel* m, const RenderOptions& options = {},
                         const std::string& camera = "top");
  ~FrameRenderer();
  FrameRenderer(FrameRenderer&&) noexcept;
  FrameRenderer& operator=(FrameRenderer&&) noexcept;
  FrameRenderer(const FrameRenderer&) = delete;
  FrameRenderer& operator=(const FrameRenderer&) = delete;

  /// Renders the state in `d` (of the same model, after mj_forward or mj_step: the kinematics must
  /// be current) as frame `frame_index` (seeds the noise). Returns a new CV_8UC3 BGR image of
  /// height_px() x width_px(), row 0 at the top of the picture. `d` is not modified.
  cv::Mat render(const mjData* d, int64_t frame_index);
  /// The same into `bgr`, reallocated only if its size or type differs (no allocation per frame).
  void render_into(const mjData* d, int64_t frame_index, cv::Mat& bgr);

  int width_px() const;
  int height_px() const;
  const RenderOptions& options() const;
  /// The GL renderer string of the context (for logs and benchmarks).
  const std::string& gl_renderer() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace airtwin
