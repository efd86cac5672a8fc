#include "sim/mujoco_runtime.h"

#include <Eigen/Geometry>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>

#include "common/errors.h"

namespace airtwin {
namespace {

// The calling thread's warnings since take_thread_warnings() last ran.
thread_local ThreadWarnings t_warnings;

// mju_error: one line, then leave without returning into MuJoCo. _Exit, not exit: other threads
// may be inside MuJoCo, and running static destructors under them would be worse than not.
extern "C" void on_mujoco_error(const char* message) {
  std::fprintf(stderr, "airtwin: MuJoCo engine error: %s\n", message ? message : "(no message)");
  std::fflush(stderr);
  std::_Exit(kMujocoErrorExitStatus);
}

// mju_warning: remember, do not print (MuJoCo also counts it in mjData::warning).
extern "C" void on_mujoco_warning(const char* message) {
  ++t_warnings.count;
  t_warnings.last_message = message ? message : "";
}

std::once_flag g_install_once;

// MuJoCo 2.2's compiler replaces the global handlers while it runs: one load at a time.
std::mutex& load_mutex() {
  static std::mutex m;
  return m;
}

}  // namespace

void install_mujoco_handlers() {
  std::call_once(g_install_once, [] {
    mju_user_error = on_mujoco_error;
    mju_user_warning = on_mujoco_warning;
  });
}

ThreadWarnings take_thread_warnings() {
  ThreadWarnings w = std::move(t_warnings);
  t_warnings = ThreadWarnings{};
  return w;
}

ModelPtr load_model_from_xml(std::string_view xml, const std::string& source) {
  install_mujoco_handlers();
  // mjVFS holds 2000 file names of 1000 chars: far too big for the stack.
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* kFile = "airtwin_scene.xml";
  // The text plus a terminating NUL, which the XML reader relies on.
  AIRTWIN_DEMAND(mj_makeEmptyFileVFS(vfs.get(), kFile, static_cast<int>(xml.size() + 1)) == 0);
  const int index = mj_findFileVFS(vfs.get(), kFile);
  AIRTWIN_DEMAND(index >= 0);
  char* file = static_cast<char*>(vfs->filedata[index]);
  std::memcpy(file, xml.data(), xml.size());
  file[xml.size()] = '\0';

  char error[1024] = "";
  mjModel* m = nullptr;
  {
    std::lock_guard<std::mutex> lock(load_mutex());
    m = mj_loadXML(kFile, vfs.get(), error, sizeof(error));
    // The compiler restores the handlers it found; make sure they are ours whatever it did.
    mju_user_error = on_mujoco_error;
    mju_user_warning = on_mujoco_warning;
  }
  mj_deleteVFS(vfs.get());
  if (!m) {
    throw InputError(source + ": MuJoCo cannot load the model: " +
                     (error[0] ? std::string(error) : std::string("unknown reason")));
  }
  return ModelPtr(m);
}

DataPtr make_data(const mjModel* m) {
  install_mujoco_handlers();
  mjData* d = mj_makeData(m);
  AIRTWIN_DEMAND(d != nullptr);
  return DataPtr(d);
}

namespace {

// cvel is [angular; linear] about the centre of mass of b's whole tree (subtree_com of its
// root), world-aligned: shift it to the point `to` of body b.
Eigen::Vector3d body_point_velocity(const mjModel* m, const mjData* d, int b, const mjtNum* to) {
  const mjtNum* cvel = d->cvel + 6 * b;
  const mjtNum* from = d->subtree_com + 3 * m->body_rootid[b];
  const Eigen::Vector3d w(cvel[0], cvel[1], cvel[2]);
  const Eigen::Vector3d v(cvel[3], cvel[4], cvel[5]);
  const Eigen::Vector3d offset(to[0] - from[0], to[1] - from[1], to[2] - from[2]);
  return v + w.cross(offset);
}

}  // namespace

Eigen::Vector3d body_com_velocity(const mjModel* m, const mjData* d, int b) {
  return body_point_velocity(m, d, b, d->xipos + 3 * b);
}

Eigen::Vector3d body_origin_velocity(const mjModel* m, const mjData* d, int b) {
  return body_point_velocity(m, d, b, d->xpos + 3 * b);
}

}  // namespace airtwin
