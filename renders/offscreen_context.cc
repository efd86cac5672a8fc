#include "renders/offscreen_context.h"

#include <GL/osmesa.h>

#include <cstdio>
#include <mutex>
#include <shared_mutex>
#include <vector>

#include "common/errors.h"
#include "sim/mujoco_runtime.h"

namespace airtwin {
namespace {

// MuJoCo 2.2 fills process-wide GL function pointers in mjr_makeContext; OSMesa's own
// bookkeeping of new contexts is not documented as thread-safe either. One creation at a time,
// and no drawing while a creation rewrites those pointers: creation holds this exclusively,
// drawing (gl_use) shares it.
std::shared_mutex& gl_mutex() {
  static std::shared_mutex m;
  return m;
}

// glGetString through OSMesa, so that nothing here links libGL (stack.md: the GL loader of
// MuJoCo 2.2 must find OSMesa's entry points, and a stray libEGL breaks it).
std::string gl_string(GLenum name) {
  using GetString = const GLubyte* (*)(GLenum);
  const auto get = reinterpret_cast<GetString>(OSMesaGetProcAddress("glGetString"));
  if (!get) return {};
  const GLubyte* s = get(name);
  return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
}

// "4.5 (Compatibility Profile) Mesa 22.3.6" -> 4 * 10 + 5; 0 when unreadable.
int gl_version_times_ten(const std::string& version) {
  int major = 0, minor = 0;
  if (std::sscanf(version.c_str(), "%d.%d", &major, &minor) != 2) return 0;
  return 10 * major + minor;
}

}  // namespace

struct OffscreenContext::Impl {
  OSMesaContext osmesa = nullptr;
  // OSMesa's default framebuffer (RGBA bytes). MuJoCo draws into its own offscreen FBO, but the
  // context needs a bound buffer to be current; it is kept at the FBO's size.
  std::vector<unsigned char> window;
  int width = 0, height = 0, samples = 0;
  mjrContext con;
  bool con_made = false;
  std::string renderer;

  void bind() {
    if (!OSMesaMakeCurrent(osmesa, window.data(), GL_UNSIGNED_BYTE, width, height)) {
      throw RenderError("OSMesa: cannot make the offscreen context current on this thread");
    }
  }

  ~Impl() {
    // MuJoCo's GL objects belong to this context: free them with it current.
    const std::shared_lock hold(gl_mutex());
    if (osmesa && con_made &&
        OSMesaMakeCurrent(osmesa, window.data(), GL_UNSIGNED_BYTE, width, height)) {
      mjr_freeContext(&con);
    }
    if (osmesa) OSMesaDestroyContext(osmesa);
  }
};

OffscreenContext::OffscreenContext(const mjModel* m, int multisamples)
    : impl_(std::make_unique<Impl>()) {
  AIRTWIN_DEMAND(m != nullptr);
  install_mujoco_handlers();
  // The model's offscreen buffer size and the sample count: user input, checked before any GL.
  Impl& s = *impl_;
  s.width = m->vis.global.offwidth;
  s.height = m->vis.global.offheight;
  if (s.width <= 0 || s.height <= 0) {
    throw InputError(
        "model: <visual><global offwidth offheight> must be > 0 for offscreen "
        "rendering, got " +
        std::to_string(s.width) + " x " + std::to_string(s.height));
  }
  if (multisamples < 0) {
    throw InputError("offscreen context: multisamples must be >= 0, got " +
                     std::to_string(multisamples));
  }
  s.samples = multisamples;
  s.window.assign(static_cast<size_t>(s.width) * s.height * 4, 0);
  mjr_defaultContext(&s.con);

  const std::unique_lock lock(gl_mutex());
  // The OSMesa context: RGBA, 24-bit depth, 8-bit stencil, 8-bit accumulation (what MuJoCo's own
  // OSMesa sample asks for), bound to the calling thread.
  s.osmesa = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 8, nullptr);
  if (!s.osmesa) {
    throw RenderError(
        "OSMesa: cannot create an RGBA offscreen context (is libosmesa6 "
        "installed?)");
  }
  s.bind();
  // MuJoCo 2.2's offscreen rendering needs framebuffer objects (core since GL 3.0).
  s.renderer = gl_string(GL_RENDERER);
  const std::string version = gl_string(GL_VERSION);
  if (gl_version_times_ten(version) < 30 &&
      gl_string(GL_EXTENSIONS).find("GL_ARB_framebuffer_object") == std::string::npos) {
    throw RenderError("OSMesa: OpenGL '" + version + "' (" + s.renderer +
                      ") has no framebuffer objects; MuJoCo needs them for offscreen rendering");
  }
  // MuJoCo reads the sample count from the model: give it a private copy with ours.
  ModelPtr copy(mj_copyModel(nullptr, m));
  AIRTWIN_DEMAND(copy != nullptr);
  copy->vis.quality.offsamples = multisamples;
  mjr_makeContext(copy.get(), &s.con, mjFONTSCALE_50);
  s.con_made = true;
  if (s.con.offFBO == 0 || s.con.offWidth != s.width || s.con.offHeight != s.height) {
    throw RenderError("MuJoCo: no offscreen framebuffer of " + std::to_string(s.width) + " x " +
                      std::to_string(s.height) + " px in the OSMesa context (" + s.renderer + ")");
  }
  mjr_setBuffer(mjFB_OFFSCREEN, &s.con);
}

OffscreenContext::~OffscreenContext() = default;

void OffscreenContext::make_current() {
  impl_->bind();
  mjr_setBuffer(mjFB_OFFSCREEN, &impl_->con);
}

std::shared_lock<std::shared_mutex> OffscreenContext::gl_use() const {
  return std::shared_lock(gl_mutex());
}

const mjrContext* OffscreenContext::mjr() const { return &impl_->con; }
int OffscreenContext::width_px() const { return impl_->width; }
int OffscreenContext::height_px() const { return impl_->height; }
int OffscreenContext::multisamples() const { return impl_->con.offSamples; }
const std::string& OffscreenContext::gl_renderer() const { return impl_->renderer; }

}  // namespace airtwin
