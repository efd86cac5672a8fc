#pragma once
// The one place that wraps MuJoCo's process-wide C machinery: its error and warning handlers, its
// model loader, and the owning pointers for mjModel / mjData.
//
// Errors. MuJoCo 2.2 calls mju_error on conditions it cannot continue from (its stack allocator
// overflowing, a corrupt model). Without a handler it prints "Press Enter to exit" and waits on
// stdin, which hangs batch runs. The handler installed here writes one line,
//   airtwin: MuJoCo engine error: <message>
// to stderr and ends the process with kMujocoErrorExitStatus. It never returns into MuJoCo (whose
// caller would then continue on a broken state) and never throws through MuJoCo's C frames.
//
// Warnings (contact buffer full, bad qacc, ...) are counted by MuJoCo in mjData::warning per
// twin. The handler installed here only keeps the calling thread's last message and a count, so
// nothing is printed at every step; the twin reports the counts.
//
// Loading. MuJoCo 2.2's XML compiler swaps the global handlers for its own while it compiles, so
// loads are serialised by a process-wide mutex and the handlers are checked again afterwards.

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <mujoco/mujoco.h>

namespace airtwin {

/// Exit status of a process ended by a MuJoCo engine error (1 and 2 are input and usage errors).
inline constexpr int kMujocoErrorExitStatus = 3;

/// The twin's state became unusable (NaN, divergence, a fault inside a callback). The message
/// names the object and the simulated time where known.
class SimulationError : public std::runtime_error {
 public:
  explicit SimulationError(const std::string& message) : std::runtime_error(message) {}
};

/// Installs the error and warning handlers. Idempotent and thread-safe (std::call_once); every
/// function of sim/ that touches MuJoCo calls it, so callers rarely need to.
void install_mujoco_handlers();

/// MuJoCo warnings seen by the handler on the calling thread since the last call (then reset).
struct ThreadWarnings {
  int count = 0;
  std::string last_message;
};
ThreadWarnings take_thread_warnings();

struct MjModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct MjDataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, MjModelDeleter>;
using DataPtr = std::unique_ptr<mjData, MjDataDeleter>;

/// A file an MJCF model refers to by a relative name (a mesh), held in memory.
struct ModelFile {
  std::string name;   ///< as the MJCF names it, e.g. "hemisphere.stl"
  std::string bytes;  ///< its contents
};

/// Compiles MJCF text held in memory (through an mjVFS, no temporary file), with the files it
/// refers to. `source` names the model in messages. Throws InputError
/// "<source>: MuJoCo cannot load the model: <reason>".
ModelPtr load_model_from_xml(std::string_view xml, const std::string& source,
                             const std::vector<ModelFile>& files = {});

/// Compiles an MJCF file; the files it refers to are read relative to its folder. Throws
/// InputError "<path>: MuJoCo cannot load the model: <reason>".
ModelPtr load_model_from_file(const std::string& path);

/// MuJoCo's own MJCF of a compiled model: compiles `xml` as load_model_from_xml does, lets
/// `edit` change the compiled model's numbers, and writes the model back as MJCF (mj_saveLastXML:
/// composites expanded into their bodies, joints, equalities and skins; positions, masses,
/// inertias, geom sizes, friction, solver parameters and options copied back from the edited
/// model, at 17 significant digits so that every double reads back exactly). What mj_saveLastXML
/// does not copy back from an mjModel (collision masks among others) is written as compiled,
/// not as edited. Meshes and skins given by vertex lists are printed at 6 digits (MuJoCo 2.2's
/// writer), so meshes are best given as files. Throws InputError as load_model_from_xml.
std::string compiled_model_xml(std::string_view xml, const std::string& source,
                               const std::vector<ModelFile>& files,
                               const std::function<void(mjModel*)>& edit);

/// A fresh mjData for `m`; aborts (AIRTWIN_DEMAND) if MuJoCo cannot allocate it.
DataPtr make_data(const mjModel* m);

/// Linear velocity (m/s, world frame) of body b's centre of mass (xipos), from mjData::cvel
/// (valid after mj_forward's velocity stage, e.g. inside mjcb_passive).
Eigen::Vector3d body_com_velocity(const mjModel* m, const mjData* d, int b);

/// Linear velocity (m/s, world frame) of body b's frame origin (xpos), the same way.
Eigen::Vector3d body_origin_velocity(const mjModel* m, const mjData* d, int b);

}  // namespace airtwin
