#pragma once
// An offscreen OpenGL context without a display or a GPU: Mesa's OSMesa (llvmpipe, software
// rasterisation) holding the GL state, and MuJoCo's mjrContext (textures, meshes, skins and the
// offscreen framebuffer of one mjModel) living inside it.
//
// Threading. An OpenGL context is current on at most one thread at a time, and MuJoCo's mjr_*
// functions draw into whatever context is current on the calling thread. Hence: one
// OffscreenContext per thread. make_current() binds it to the calling thread (FrameRenderer does
// this before every frame, so two contexts may also take turns on one thread); using one context
// from two threads at once is a bug. Contexts in different threads render concurrently (tested in
// tests/renders/offscreen_context_test.cc). Creation is serialised by a process-wide lock,
// because MuJoCo 2.2 loads its GL function pointers into process-wide globals when it makes a
// context; drawing holds the same lock shared (gl_use), so that no thread calls through those
// pointers while another thread's creation rewrites them (a batch of --vision runs creates a
// context per run while other runs draw).
//
// Errors. Everything that can be checked before MuJoCo touches GL is checked here and throws
// RenderError (no OSMesa context, no framebuffer objects) or InputError (a model without an
// offscreen buffer size). A failure inside mjr_makeContext itself is a MuJoCo engine error: the
// handler of sim/mujoco_runtime.h prints one line and ends the process with status 3 (it never
// waits for "Press Enter").
//
// The look of the frames is not decided here: multisampling, the only context-level setting, is
// an argument (FrameRenderer passes 0 by default, see docs/rendering.md).

#include <memory>
#include <shared_mutex>
#include <stdexcept>
#include <string>

#include <mujoco/mujoco.h>

namespace airtwin {

/// The offscreen GL context could not be created or used (missing OSMesa, GL too old).
class RenderError : public std::runtime_error {
 public:
  explicit RenderError(const std::string& message) : std::runtime_error(message) {}
};

class OffscreenContext {
 public:
  /// Creates an OSMesa RGBA context (24-bit depth, 8-bit stencil, 8-bit accumulation), makes it
  /// current on the calling thread and builds MuJoCo's rendering context for `m` with an offscreen
  /// framebuffer of the model's <visual><global offwidth offheight> (px) and `multisamples`
  /// samples per pixel (0 = off; MuJoCo's default of 4 makes a frame ~5-10x slower here).
  /// `m` is only read during construction; the context keeps uploaded copies of its meshes,
  /// textures and skins, so render with the same model. Throws InputError when the model has no
  /// offscreen size or `multisamples` is negative, RenderError when OSMesa or GL fail.
  explicit OffscreenContext(const mjModel* m, int multisamples = 0);
  /// Makes the context current on the calling thread and frees MuJoCo's GL objects and OSMesa's.
  ~OffscreenContext();
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;

  /// Binds the context to the calling thread and selects MuJoCo's offscreen framebuffer. Throws
  /// RenderError if OSMesa refuses.
  void make_current();

  /// Hold this for the duration of GL calls through MuJoCo (mjr_render, mjr_readPixels, ...):
  /// shared between drawing threads, exclusive of context creation (see Threading above).
  std::shared_lock<std::shared_mutex> gl_use() const;

  /// MuJoCo's rendering context (valid while this object lives, used on the current thread).
  const mjrContext* mjr() const;
  int width_px() const;   ///< offscreen framebuffer width (px)
  int height_px() const;  ///< offscreen framebuffer height (px)
  /// Multisamples per pixel of the offscreen buffer as granted (GL may round a request up).
  int multisamples() const;
  /// The GL_RENDERER string of the context ("llvmpipe (LLVM 15.0.6, 256 bits)").
  const std::string& gl_renderer() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace airtwin
