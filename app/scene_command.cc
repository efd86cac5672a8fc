// airtwin scene: the scene the twin simulates as MJCF files, for MuJoCo's own viewer (`simulate`),
// for editing, and for `run --mjcf`. Writes DIR/scene.xml (MuJoCo's own MJCF of the compiled
// scene, sim/scene_builder.h export_scene) and the files it names beside it.

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "app/cli_common.h"
#include "app/commands.h"
#include "common/errors.h"
#include "scenes/scenario.h"
#include "sim/scene_builder.h"
#include "sim/twin.h"

namespace airtwin::cli {
namespace {

struct SceneArgs {
  std::string scenario;
  bool rig = false;
  std::string out;
  uint64_t seed = 0;
  std::vector<std::string> effects;
  AirFlags air;
};

void run_scene(const SceneArgs& a) {
  if (a.rig == !a.scenario.empty()) {
    throw UsageError(a.rig ? "give a scenario file or --rig, not both"
                           : "a scenario file or --rig is required");
  }
  // The twin's physics as `run` sets it from the same flags.
  TwinParameters twin;
  apply_air_flags(a.air, &twin);
  apply_effect_flags(a.effects, &twin);
  SceneSpec spec;
  spec.source = "the rig";
  if (!a.rig) spec = read_scenario(a.scenario).scene;

  const SceneExport scene = export_scene(spec, twin.scene, a.seed);
  write_text_file(a.out + "/scene.xml", scene.xml);
  std::string written = "scene.xml";
  for (const ModelFile& f : scene.files) {
    write_text_file(a.out + "/" + f.name, f.bytes);
    written += ", " + f.name;
  }
  std::printf("wrote %s/%s (%zu objects, seed %llu)\n", a.out.c_str(), written.c_str(),
              spec.objects.size(), static_cast<unsigned long long>(a.seed));
}

}  // namespace

void add_scene_command(CLI::App& app) {
  auto args = std::make_shared<SceneArgs>();
  CLI::App* sub = app.add_subcommand(
      "scene",
      "Write the scene the twin simulates as MuJoCo MJCF: DIR/scene.xml and the files it names\n"
      "beside it (hemisphere.stl, the tracers' mesh). It is MuJoCo's own MJCF of the compiled\n"
      "scene (cotton composites expanded, wads shaped, headings drawn from --seed), so that\n"
      "mj_loadXML and MuJoCo's `simulate` viewer compile the same model the twin steps. Edit it\n"
      "and run it with `airtwin run SCENARIO --mjcf DIR/scene.xml` (same --seed for the same\n"
      "wads); docs/twin.md says what the twin needs from it. --rig: the rig without objects.");
  sub->add_option("scenario", args->scenario, "Scenario file (YAML)");
  sub->add_flag("--rig", args->rig, "The empty rig: floor, camera, nozzle, no objects");
  sub->add_option("--out", args->out, "Output folder")->required();
  sub->add_option("--seed", args->seed, "Seed of the headings not given and the wads' shapes")
      ->capture_default_str();
  sub->add_option("--effect", args->effects,
                  "A physical effect as `run` takes it, NAME:k=v,... (repeatable); floor_slope\n"
                  "tilts the scene's gravity");
  add_air_flags(sub, args->air);
  sub->callback([args] { run_scene(*args); });
}

}  // namespace airtwin::cli
