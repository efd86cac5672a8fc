// `airtwin scene` end to end: the exported MJCF compiles (with MuJoCo's own mj_loadXML, from the
// file) to the model the twin builds, array for array; the shipped scenes/rig.xml is what the
// command writes today; `run --mjcf` and `batch --mjcf` on an unedited export repeat the plain
// runs bit for bit and an edited one changes them; the batch's manifest names the scene and its
// hash; bad input is one line, for `run`, `batch` and `view` alike.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <mujoco/mjxmacro.h>
#include <mujoco/mujoco.h>
#include <nlohmann/json.hpp>

#include "models/air_field.h"
#include "scenes/scenario.h"
#include "sim/twin.h"
#include "tests/app/cli_runner.h"

namespace airtwin {
namespace {

using testing::count_lines;
using testing::file_text;
using testing::run_airtwin;
using testing::scratch_dir;

const std::string kScenes = std::string(AIRTWIN_SOURCE_DIR) + "/scenes/";

void write(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// `text` with the one occurrence of `from` replaced by `to` (fails the test unless there is
// exactly one).
std::string replace_once(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at == std::string::npos) return text;
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

// The compiled model of an MJCF file, by MuJoCo alone.
struct LoadedModel {
  mjModel* m = nullptr;
  std::string error;
  explicit LoadedModel(const std::string& path) {
    char buffer[1024] = "";
    m = mj_loadXML(path.c_str(), nullptr, buffer, sizeof(buffer));
    error = buffer;
  }
  ~LoadedModel() { mj_deleteModel(m); }
};

// One mjModel array that differs: its name and the largest difference, relative to the larger
// magnitude of the two (1 for a count or an index).
struct Difference {
  std::string field;
  double relative = 0.0;
};

template <typename T>
void compare_array(const char* name, const T* a, const T* b, long n, std::vector<Difference>* out) {
  double worst = 0.0;
  bool differs = false;
  for (long i = 0; i < n; ++i) {
    if (a[i] == b[i]) continue;
    differs = true;
    const double x = static_cast<double>(a[i]), y = static_cast<double>(b[i]);
    worst = std::max(worst, std::abs(x - y) / std::max(std::abs(x), std::abs(y)));
  }
  if (differs) out->push_back({name, worst});
}

// Every size and every array of two models (mjxmacro.h's lists), and the option, visual and
// statistic structs.
std::vector<Difference> model_differences(const mjModel* a, const mjModel* b) {
  std::vector<Difference> out;
#define X(name) \
  if (a->name != b->name) out.push_back({#name, 1.0});
  MJMODEL_INTS
#undef X
  if (!out.empty()) return out;  // the arrays' lengths differ
  {
    MJMODEL_POINTERS_PREAMBLE(a)
#define X(type, name, n1, n2) \
  compare_array(#name, a->name, b->name, static_cast<long>(a->n1) * (n2), &out);
    MJMODEL_POINTERS
#undef X
  }
  if (std::memcmp(&a->opt, &b->opt, sizeof(mjOption)) != 0) out.push_back({"opt", 1.0});
  if (std::memcmp(&a->vis, &b->vis, sizeof(mjVisual)) != 0) out.push_back({"vis", 1.0});
  if (std::memcmp(&a->stat, &b->stat, sizeof(mjStatistic)) != 0) out.push_back({"stat", 1.0});
  return out;
}

TEST(SceneCli, ExportCompilesToTheTwinsModel) {
  // sorting: three tracers (mesh file) and three cotton wads (composites shaped from the seed).
  const std::string d = scratch_dir("scene_sorting");
  const auto r = run_airtwin("scene " + kScenes + "sorting.yaml --seed 3 --out " + d);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(file_text(d + "/scene.xml").find(d), std::string::npos) << "no machine paths";
  const LoadedModel exported(d + "/scene.xml");
  ASSERT_NE(exported.m, nullptr) << exported.error;

  // The twin `scene` exports by default: physical drag (its friction is the physical law's).
  const Scenario scenario = read_scenario(kScenes + "sorting.yaml");
  TwinParameters params;
  params.scene.tracer.use_physical_drag();
  params.scene.cotton.use_physical_drag();
  const Twin twin(scenario.scene, params, AirFieldModel::with_constructed_table(), 3);
  const mjModel* m = twin.model();
  // The twin's model has the objects this test is about.
  ASSERT_EQ(twin.object_count(), 6u);
  EXPECT_EQ(m->nmesh, 1);
  EXPECT_EQ(m->nskin, 3);
  EXPECT_GT(m->nbody, 3 * 27);

  // Every array of mjModel (bodies, masses, inertias, geoms, friction, solref/solimp, contact
  // masks, joints, equalities, camera, qpos0, meshes, skins, ...) and the options, equal to the
  // last bit: the twin compiles the exported text itself, so no tolerance is needed, and any
  // change the twin made to its model after compiling would show here.
  for (const Difference& diff : model_differences(exported.m, m)) {
    ADD_FAILURE() << diff.field << " differs, by " << diff.relative << " relative";
  }
  // Spelled out for the reader: the fields the issue names.
  EXPECT_EQ(exported.m->nbody, m->nbody);
  EXPECT_EQ(exported.m->ngeom, m->ngeom);
  EXPECT_EQ(exported.m->njnt, m->njnt);
  EXPECT_EQ(exported.m->opt.timestep, m->opt.timestep);
  EXPECT_EQ(exported.m->opt.integrator, m->opt.integrator);
  EXPECT_EQ(exported.m->opt.cone, m->opt.cone);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(exported.m->opt.gravity[k], m->opt.gravity[k]);
  for (int b = 0; b < m->nbody; ++b) {
    EXPECT_EQ(exported.m->body_mass[b], m->body_mass[b]) << b;
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(exported.m->body_inertia[3 * b + k], m->body_inertia[3 * b + k]) << b;
      EXPECT_EQ(exported.m->body_pos[3 * b + k], m->body_pos[3 * b + k]) << b;
    }
  }
  for (int g = 0; g < m->ngeom; ++g) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(exported.m->geom_size[3 * g + k], m->geom_size[3 * g + k]) << g;
      EXPECT_EQ(exported.m->geom_friction[3 * g + k], m->geom_friction[3 * g + k]) << g;
    }
    EXPECT_EQ(exported.m->geom_contype[g], m->geom_contype[g]) << g;
    EXPECT_EQ(exported.m->geom_conaffinity[g], m->geom_conaffinity[g]) << g;
    for (int k = 0; k < mjNREF; ++k) {
      EXPECT_EQ(exported.m->geom_solref[mjNREF * g + k], m->geom_solref[mjNREF * g + k]);
    }
    for (int k = 0; k < mjNIMP; ++k) {
      EXPECT_EQ(exported.m->geom_solimp[mjNIMP * g + k], m->geom_solimp[mjNIMP * g + k]);
    }
  }
  for (int k = 0; k < 3; ++k) EXPECT_EQ(exported.m->cam_pos[k], m->cam_pos[k]);
  EXPECT_EQ(exported.m->cam_fovy[0], m->cam_fovy[0]);
}

TEST(SceneCli, ShippedRigIsWhatTheCommandWrites) {
  const std::string d = scratch_dir("scene_rig");
  const auto r = run_airtwin("scene --rig --out " + d);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // scenes/README.md says how to regenerate it when this fails after a change to the scene.
  EXPECT_EQ(file_text(d + "/scene.xml"), file_text(kScenes + "rig.xml"));
  const LoadedModel rig(kScenes + "rig.xml");
  ASSERT_NE(rig.m, nullptr) << rig.error;
  EXPECT_GE(mj_name2id(rig.m, mjOBJ_JOINT, "nozzle_pan"), 0);
  EXPECT_GE(mj_name2id(rig.m, mjOBJ_JOINT, "nozzle_tilt"), 0);
  EXPECT_GE(mj_name2id(rig.m, mjOBJ_CAMERA, "top"), 0);
  EXPECT_EQ(mj_name2id(rig.m, mjOBJ_BODY, "obj0"), -1);
  EXPECT_EQ(rig.m->nmesh, 0);  // no tracer, no mesh file: the file stands alone
}

TEST(SceneCli, BadInputIsOneLine) {
  const std::string d = scratch_dir("scene_bad");
  // A scenario that does not exist: bad input, named.
  auto r = run_airtwin("scene " + d + "/nothing.yaml --out " + d);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("nothing.yaml"), std::string::npos) << r.err;
  // Neither a scenario nor --rig, or both: usage errors.
  r = run_airtwin("scene --out " + d);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--rig"), std::string::npos) << r.err;
  r = run_airtwin("scene " + kScenes + "line.yaml --rig --out " + d);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_FALSE(std::ifstream(d + "/scene.xml").good());
}

// sorting, cut to 3 s: both object types, and quick.
std::string short_sorting(const std::string& dir) {
  const std::string path = dir + "/sorting_3s.yaml";
  write(path,
        replace_once(file_text(kScenes + "sorting.yaml"), "time_limit_s: 60", "time_limit_s: 3"));
  return path;
}

TEST(SceneCli, RunOnTheExportRepeatsThePlainRunAndAnEditChangesIt) {
  const std::string d = scratch_dir("scene_run");
  const std::string scenario = short_sorting(d);
  ASSERT_EQ(run_airtwin("scene " + scenario + " --seed 5 --out " + d + "/scene").exit_code, 0);
  // The floor's friction edited in the text: 0 (the objects' own coefficients decide, as MuJoCo
  // takes the larger of a pair) to 1.5, more than any object's.
  const std::string xml = file_text(d + "/scene/scene.xml");
  const size_t floor = xml.find("<geom name=\"floor\"");
  ASSERT_NE(floor, std::string::npos);
  const std::string element = xml.substr(floor, xml.find("/>", floor) - floor);
  write(d + "/scene/edited.xml",
        replace_once(xml, element,
                     replace_once(element, "friction=\"0 0 0\"", "friction=\"1.5 0 0\"")));

  const std::string common = "run " + scenario + " --seed 5 --quiet --out " + d;
  auto r = run_airtwin(common + "/plain");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_airtwin(common + "/exported --mjcf " + d + "/scene/scene.xml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_airtwin(common + "/edited --mjcf " + d + "/scene/edited.xml");
  ASSERT_EQ(r.exit_code, 0) << r.err;

  const std::string plain = file_text(d + "/plain/log.csv");
  ASSERT_GT(count_lines(plain), 100);
  EXPECT_TRUE(plain == file_text(d + "/exported/log.csv"))
      << "the unedited export runs differently";
  EXPECT_EQ(file_text(d + "/plain/nozzle.csv"), file_text(d + "/exported/nozzle.csv"));
  EXPECT_FALSE(plain == file_text(d + "/edited/log.csv")) << "the floor's friction changed nothing";
}

TEST(SceneCli, RunNamesWhatAUserSceneLacks) {
  const std::string d = scratch_dir("scene_missing");
  const std::string scenario = short_sorting(d);
  ASSERT_EQ(run_airtwin("scene " + scenario + " --out " + d + "/scene").exit_code, 0);
  // The first object's body renamed: the twin cannot find tracer t1.
  write(d + "/scene/renamed.xml",
        replace_once(file_text(d + "/scene/scene.xml"), "name=\"obj0\"", "name=\"tracer_t1\""));
  const auto r = run_airtwin("run " + scenario + " --quiet --mjcf " + d +
                             "/scene/renamed.xml --out " + d + "/run");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("renamed.xml: body 'obj0' (tracer 't1', objects[0] of the scenario) not "
                       "found; expected a body named 'obj0'"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(std::ifstream(d + "/run/log.csv").good());
}

// line, cut to 16 s: one tracer, which starts moving at 13 s in seed 1; a run of ~1 s.
std::string short_line(const std::string& dir) {
  const std::string path = dir + "/line_16s.yaml";
  write(path,
        replace_once(file_text(kScenes + "line.yaml"), "time_limit_s: 120", "time_limit_s: 16"));
  return path;
}

// The export of `scenario` with seed 1 in DIR/scene, and beside it heavy.xml: the same with the
// tracer ten times heavier (mass and inertia). Eq. (8)'s drag and the friction scale with the
// mass the twin compiles from the file, but the pressure push near s does not (it acts on the
// volume, sim/air_forces.h), so the heavier tracer is pushed off less and moves otherwise.
void export_with_heavy_tracer(const std::string& scenario, const std::string& dir) {
  ASSERT_EQ(run_airtwin("scene " + scenario + " --seed 1 --out " + dir + "/scene").exit_code, 0);
  write(dir + "/scene/heavy.xml",
        replace_once(file_text(dir + "/scene/scene.xml"),
                     "mass=\"0.00016000000000000001\" diaginertia=\"9.3375000000000001e-09 "
                     "9.3375000000000001e-09 1.44e-08\"",
                     "mass=\"0.0016000000000000001\" diaginertia=\"9.3375000000000001e-08 "
                     "9.3375000000000001e-08 1.44e-07\""));
}

// FNV-1a 64 of a file's bytes as 16 hex digits, computed here from its definition.
std::string fnv1a(const std::string& bytes) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (const unsigned char c : bytes) h = (h ^ c) * 0x100000001b3ull;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

// runs.csv's row of `seed` (its second column), "" if none.
std::string row_of_seed(const std::string& runs_csv, int seed) {
  std::istringstream in(runs_csv);
  for (std::string row; std::getline(in, row);) {
    const size_t comma = row.find(',');
    if (comma != std::string::npos &&
        row.substr(comma + 1, row.find(',', comma + 1) - comma - 1) == std::to_string(seed)) {
      return row;
    }
  }
  return "";
}

TEST(SceneCli, BatchOnTheExportRepeatsThePlainBatchAndAnEditChangesIt) {
  const std::string d = scratch_dir("scene_batch");
  const std::string scenario = short_line(d);
  export_with_heavy_tracer(scenario, d);
  const std::string batch = "batch " + scenario + " --seeds 2 --jobs 1 --quiet ";
  for (const auto& [dir, flags] : std::vector<std::pair<std::string, std::string>>{
           {"plain", ""},
           {"exported", "--mjcf " + d + "/scene/scene.xml"},
           {"again", "--mjcf " + d + "/scene/scene.xml"},
           {"heavy", "--mjcf " + d + "/scene/heavy.xml"}}) {
    const auto r = run_airtwin(batch + flags + " --out " + d + "/" + dir);
    ASSERT_EQ(r.exit_code, 0) << dir << ": " << r.err;
  }
  const std::string exported = file_text(d + "/exported/runs.csv");
  ASSERT_EQ(count_lines(exported), 3) << exported;  // the header and seeds 1 and 2
  // The same inputs, the same bytes.
  EXPECT_EQ(exported, file_text(d + "/again/runs.csv"));
  // Seed 1 is the export's seed: the unedited scene runs as the built one. (Seed 2's built scene
  // draws the tracer's heading from seed 2, the file keeps seed 1's.)
  const std::string plain = file_text(d + "/plain/runs.csv");
  ASSERT_FALSE(row_of_seed(plain, 1).empty()) << plain;
  EXPECT_EQ(row_of_seed(plain, 1), row_of_seed(exported, 1));
  // The heavier tracer changes both runs.
  const std::string heavy = file_text(d + "/heavy/runs.csv");
  for (int seed : {1, 2}) {
    EXPECT_NE(row_of_seed(heavy, seed), row_of_seed(exported, seed)) << "seed " << seed;
    EXPECT_FALSE(row_of_seed(heavy, seed).empty()) << heavy;
  }

  // The manifest names the scene and the mesh it loads, with hashes of their bytes.
  const auto manifest = nlohmann::json::parse(file_text(d + "/heavy/batch.json"));
  const nlohmann::json& scene = manifest["settings"]["scene"];
  EXPECT_EQ(scene["file"], d + "/scene/heavy.xml") << scene;
  EXPECT_EQ(scene["content_hash"], fnv1a(file_text(d + "/scene/heavy.xml"))) << scene;
  ASSERT_EQ(scene["assets"].size(), 1u) << scene;
  EXPECT_EQ(scene["assets"][0]["content_hash"], fnv1a(file_text(d + "/scene/hemisphere.stl")));
  EXPECT_EQ(nlohmann::json::parse(file_text(d + "/plain/batch.json"))["settings"]["scene"],
            "built");
  // So a batch is not resumed with another scene, nor with the same file after an edit.
  auto r = run_airtwin(batch + "--mjcf " + d + "/scene/scene.xml --out " + d + "/heavy");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("/settings/scene/content_hash"), std::string::npos) << r.err;
  r = run_airtwin(batch + "--out " + d + "/heavy");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("/settings/scene"), std::string::npos) << r.err;
}

TEST(SceneCli, BatchAndViewNameWhatAUserSceneLacks) {
  const std::string d = scratch_dir("scene_batch_missing");
  const std::string scenario = short_line(d);
  ASSERT_EQ(run_airtwin("scene " + scenario + " --out " + d + "/scene").exit_code, 0);
  // The camera renamed: the twin renders through `top`.
  write(d + "/scene/renamed.xml", replace_once(file_text(d + "/scene/scene.xml"),
                                               "<camera name=\"top\"", "<camera name=\"above\""));
  const std::string expected = "renamed.xml: camera 'top' not found";
  auto r = run_airtwin("batch " + scenario + " --seeds 2 --quiet --mjcf " + d +
                       "/scene/renamed.xml --out " + d + "/batch");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(d + "/batch")) << "nothing is written for a bad scene";
  // Two scenarios against one scene: the message says which one the scene does not fit.
  r = run_airtwin("batch " + scenario + " " + short_sorting(d) + " --seeds 1 --quiet --mjcf " + d +
                  "/scene/scene.xml --out " + d + "/batch");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("(scenario " + d + "/sorting_3s.yaml)"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(d + "/batch"));
  // view checks the scene before it looks for a display or opens a window.
  r = run_airtwin("view " + scenario + " --mjcf " + d + "/scene/renamed.xml");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  // A file MuJoCo cannot parse at all.
  write(d + "/scene/broken.xml", "<mujoco><worldbody>");
  r = run_airtwin("view " + scenario + " --mjcf " + d + "/scene/broken.xml");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("broken.xml"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace airtwin
