#include "sim/mujoco_runtime.h"

#include <Eigen/Geometry>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>

#include <unistd.h>

#include "common/errors.h"

// MuJoCo 2.2.2 exports these (src/xml/xml_numeric_format.h, which Debian does not install): the
// number of significant digits its XML writer prints, per thread, 6 unless set. MuJoCo's own
// tests set 17 to save models that read back exactly.
extern "C" int _mjPRIVATE__get_xml_precision();
extern "C" void _mjPRIVATE__set_xml_precision(int precision);

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

namespace {

// An mjVFS holding `xml` under `name` and `files` under theirs. mjVFS holds 2000 file names of
// 1000 chars: far too big for the stack.
struct Vfs {
  std::unique_ptr<mjVFS> vfs = std::make_unique<mjVFS>();
  Vfs() { mj_defaultVFS(vfs.get()); }
  ~Vfs() { mj_deleteVFS(vfs.get()); }
  Vfs(const Vfs&) = delete;
  Vfs& operator=(const Vfs&) = delete;

  // Adds a file; `nul` appends a terminating NUL, which the XML reader relies on.
  void add(const std::string& name, std::string_view bytes, bool nul) {
    const size_t size = bytes.size() + (nul ? 1 : 0);
    AIRTWIN_DEMAND(mj_makeEmptyFileVFS(vfs.get(), name.c_str(), static_cast<int>(size)) == 0);
    const int index = mj_findFileVFS(vfs.get(), name.c_str());
    AIRTWIN_DEMAND(index >= 0);
    char* file = static_cast<char*>(vfs->filedata[index]);
    std::memcpy(file, bytes.data(), bytes.size());
    if (nul) file[bytes.size()] = '\0';
  }
};

constexpr const char* kVfsScene = "airtwin_scene.xml";

// mj_loadXML of `file` (from `vfs` if given) with our handlers restored afterwards; the caller
// holds load_mutex(). Throws InputError naming `source`.
ModelPtr load_locked(const char* file, const mjVFS* vfs, const std::string& source) {
  char error[1024] = "";
  mjModel* m = mj_loadXML(file, vfs, error, sizeof(error));
  // The compiler restores the handlers it found; make sure they are ours whatever it did.
  mju_user_error = on_mujoco_error;
  mju_user_warning = on_mujoco_warning;
  if (!m) {
    // MuJoCo's reason may span lines (an XML parse error does): made one line.
    std::string reason;
    for (const char* c = error; *c; ++c) {
      if (*c != '\n' && *c != '\r') {
        reason += *c;
      } else if (!reason.empty() && reason.back() != ' ' && c[1] != '\0') {
        reason += reason.back() == ':' ? " " : "; ";
      }
    }
    while (!reason.empty() && (reason.back() == ' ' || reason.back() == ';')) reason.pop_back();
    throw InputError(source + ": MuJoCo cannot load the model: " +
                     (reason.empty() ? std::string("unknown reason") : reason));
  }
  return ModelPtr(m);
}

std::unique_ptr<Vfs> scene_vfs(std::string_view xml, const std::vector<ModelFile>& files) {
  auto vfs = std::make_unique<Vfs>();
  vfs->add(kVfsScene, xml, true);
  for (const ModelFile& f : files) vfs->add(f.name, f.bytes, false);
  return vfs;
}

}  // namespace

ModelPtr load_model_from_xml(std::string_view xml, const std::string& source,
                             const std::vector<ModelFile>& files) {
  install_mujoco_handlers();
  const std::unique_ptr<Vfs> vfs = scene_vfs(xml, files);
  std::lock_guard<std::mutex> lock(load_mutex());
  return load_locked(kVfsScene, vfs->vfs.get(), source);
}

ModelPtr load_model_from_file(const std::string& path) {
  install_mujoco_handlers();
  if (!std::filesystem::is_regular_file(path)) {
    throw InputError(path + ": cannot read the file (no such file)");
  }
  std::lock_guard<std::mutex> lock(load_mutex());
  return load_locked(path.c_str(), nullptr, path);
}

std::string compiled_model_xml(std::string_view xml, const std::string& source,
                               const std::vector<ModelFile>& files,
                               const std::function<void(mjModel*)>& edit) {
  install_mujoco_handlers();
  const std::unique_ptr<Vfs> vfs = scene_vfs(xml, files);
  // mj_saveLastXML writes the model the last mj_loadXML compiled (a process-wide one) to a file:
  // load, edit and save under one lock, into a temporary file of our own.
  struct TempFile {
    std::string path = (std::filesystem::temp_directory_path() / "airtwin_mjcf_XXXXXX").string();
    ~TempFile() {
      std::error_code ignored;
      std::filesystem::remove(path, ignored);
    }
  } file;
  const int fd = mkstemp(file.path.data());
  if (fd < 0) throw InputError(file.path + ": cannot create a temporary file");
  close(fd);
  char error[1024] = "";
  int saved = 0;
  {
    std::lock_guard<std::mutex> lock(load_mutex());
    ModelPtr m = load_locked(kVfsScene, vfs->vfs.get(), source);
    edit(m.get());
    const int precision = _mjPRIVATE__get_xml_precision();
    _mjPRIVATE__set_xml_precision(17);
    saved = mj_saveLastXML(file.path.c_str(), m.get(), error, sizeof(error));
    _mjPRIVATE__set_xml_precision(precision);
    mj_freeLastXML();
  }
  std::ifstream in(file.path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!saved) {
    throw InputError(source + ": MuJoCo cannot write the model: " +
                     (error[0] ? std::string(error) : std::string("unknown reason")));
  }
  return text.str();
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
