// airtwin batch: every scenario x seed in closed loop, twins in parallel threads, resumable
// (runs/batch_runner.h); DIR/runs.csv and the report (runs/batch_report.h). A shard of the batch
// for a cluster's job array with --shard I/N, and airtwin batch-merge to put the shards' results
// together into the report of the whole batch. docs/batch.md.

#include <sched.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/cli_common.h"
#include "app/commands.h"
#include "app/progress.h"
#include "app/run_setup.h"
#include "common/csv.h"
#include "common/errors.h"
#include "runs/batch_plan.h"
#include "runs/batch_report.h"
#include "runs/batch_runner.h"
#include "runs/batch_store.h"

namespace airtwin::cli {
namespace {

using nlohmann::ordered_json;

// Seed of the checkerboard views when a vision batch calibrates the twin's camera itself (once per
// batch, as a rig's camera is calibrated once): fixed, so that every shard gets the same camera.
constexpr uint64_t kCalibrationSeed = 0;

struct BatchArgs {
  std::vector<std::string> scenarios;
  int seeds = 0;
  uint64_t first_seed = 1;
  int jobs = 0;
  std::string shard = "0/1";
  bool logs = false;
  bool quiet = false;
  std::string out;
  RunSetupFlags setup;
};

struct MergeArgs {
  std::vector<std::string> dirs;
  std::string out;
  bool quiet = false;
};

// The CPUs this process may run on (a cluster's allocation, taskset), else the machine's.
int usable_cpus() {
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

// A file's identity for the manifest: where it was (for people) and a hash of its bytes.
ordered_json file_identity(const std::string& path) {
  return {{"file", path}, {"content_hash", content_hash(read_text_file(path))}};
}

// The values of every `name="..."` attribute in an XML text, in order.
std::vector<std::string> attribute_values(const std::string& xml, const std::string& name) {
  std::vector<std::string> values;
  const std::string key = " " + name + "=\"";
  for (size_t at = xml.find(key); at != std::string::npos; at = xml.find(key, at + 1)) {
    const size_t begin = at + key.size();
    const size_t end = xml.find('"', begin);
    if (end == std::string::npos) break;
    values.push_back(xml.substr(begin, end - begin));
  }
  return values;
}

// A user's MJCF scene for the manifest: the file's identity and that of every file it names
// (`file="..."`: meshes, textures, includes), looked up as MuJoCo does, beside the scene or in the
// compiler's meshdir, texturedir or assetdir. The scene has been loaded already (check_user_scene),
// so the files it names exist.
ordered_json scene_identity(const std::string& path) {
  namespace fs = std::filesystem;
  ordered_json scene = file_identity(path);
  const std::string xml = read_text_file(path);
  const fs::path folder = fs::path(path).parent_path();
  std::vector<fs::path> dirs = {folder};
  for (const char* dir : {"meshdir", "texturedir", "assetdir"}) {
    for (const std::string& d : attribute_values(xml, dir)) dirs.push_back(folder / d);
  }
  scene["assets"] = ordered_json::array();
  for (const std::string& name : attribute_values(xml, "file")) {
    for (const fs::path& dir : dirs) {
      std::error_code ec;
      const fs::path candidate = fs::path(name).is_absolute() ? fs::path(name) : dir / name;
      if (fs::is_regular_file(candidate, ec)) {
        scene["assets"].push_back(file_identity(candidate.string()));
        break;
      }
    }
  }
  return scene;
}

// Everything besides the scenarios and seeds that a batch's results depend on.
ordered_json batch_settings(const BatchArgs& a) {
  const RunSetupFlags& f = a.setup;
  ordered_json s;
  s["perception"] = f.vision ? "vision" : "truth";
  if (f.vision) {
    s["vision"] = {{"rate_hz", f.vision_rate_hz}, {"noise", f.noise}};
    s["vision"]["calibration"] =
        f.calib.empty() ? ordered_json{{"twin_seed", kCalibrationSeed}} : file_identity(f.calib);
  }
  s["table"] = f.table.empty() ? ordered_json("built-in") : file_identity(f.table);
  s["models"] = ordered_json::array();
  for (const std::string& m : controller_models(f)) s["models"].push_back(file_identity(m));
  s["effects"] = f.effects;
  s["scene"] = f.mjcf.empty() ? ordered_json("built") : scene_identity(f.mjcf);
  s["air"] = air_identity(f.air);
  const PhysicsVariation variation = physics_variation_of(f);
  if (variation.active()) s["physics_variation"] = variation.to_string();
  s["logs"] = a.logs;
  // The program itself: another build may give other results, so it may not resume this batch.
  s["program"] = content_hash(read_text_file("/proc/self/exe"));
  return s;
}

// One line per scenario on stdout: success and the main figures.
void print_summary(const std::vector<RunRecord>& records) {
  for (const ScenarioStats& s : scenario_stats(records)) {
    std::printf("%s: %d/%d succeeded (%.0f%%)", s.scenario.c_str(), s.successes, s.runs,
                100.0 * s.success_rate);
    const Distribution& t = s.completion_time_s;
    if (t.count > 0) {
      std::printf(", completion time median %.1f s, p90 %.1f s, worst %.1f s (seed %llu)", t.median,
                  t.p90, t.worst, static_cast<unsigned long long>(t.worst_seed));
    }
    if (s.path_error_max_cm && s.path_error_max_cm->count > 0) {
      std::printf(", path error mean %.2f cm (median run), max %.2f cm (seed %llu)",
                  s.path_error_mean_cm->median, s.path_error_max_cm->worst,
                  static_cast<unsigned long long>(s.path_error_max_cm->worst_seed));
    }
    if (!s.twin_failure_seeds.empty()) {
      std::printf(", %zu twin failure(s)", s.twin_failure_seeds.size());
    }
    std::printf("\n");
  }
}

void run_batch_command(const BatchArgs& a) {
  // Flags first: nothing is read or written for a batch that cannot start.
  if (a.jobs < 0 || a.jobs > 1024) {
    throw UsageError("--jobs: expected a count in [1, 1024] (0: every usable core), got " +
                     std::to_string(a.jobs));
  }
  const Shard shard =
      with_flags({{"batch.shard", "--shard"}}, [&] { return parse_shard(a.shard); });
  check_run_setup_flags(a.setup);
  const BatchPlan plan =
      with_flags({{"batch.seed_count", "--seeds"},
                  {"batch.first_seed", "--first-seed"},
                  {"batch.scenarios", "SCENARIO"}},
                 [&] { return make_batch_plan(a.scenarios, a.first_seed, a.seeds, shard); });
  const AirFieldModel field = field_model_of(a.setup);
  BatchRunOptions options;
  options.run = run_options_of(a.setup);
  // --mjcf: the one scene must hold every scenario's objects; checked before the folder is made.
  for (const BatchScenario& s : plan.scenarios) {
    try {
      check_user_scene(a.setup, s.scenario, options.run);
    } catch (const InputError& e) {
      if (plan.scenarios.size() == 1) throw;
      throw InputError(std::string(e.what()) + " (scenario " + s.file + ")");
    }
  }
  options.jobs = a.jobs > 0 ? a.jobs : usable_cpus();
  options.keep_logs = a.logs;

  // The folder: new, or the same batch started before (then only unfinished runs are run).
  const BatchManifest manifest = BatchManifest::of_plan(plan, batch_settings(a));
  const BatchStore store(a.out, manifest);
  if (a.setup.vision) {
    // The camera model: --calib's, the one this batch calibrated before, or calibrate now.
    const std::string saved = a.out + "/calib.yaml";
    std::error_code ec;
    options.run.vision_camera =
        a.setup.calib.empty() && std::filesystem::exists(saved, ec)
            ? CalibratedCamera::read(saved)
            : vision_camera_of(a.setup, options.run, a.out, kCalibrationSeed);
  }

  // Progress on stderr (a bar on a terminal, plain lines otherwise).
  const int total = static_cast<int>(plan.shard_runs().size());
  std::unique_ptr<Progress> progress;
  int finished_before = 0;
  options.on_start = [&](int before, int to_run) {
    finished_before = before;
    std::printf("batch: %zu scenario(s) x %d seed(s) from %llu", plan.scenarios.size(),
                plan.seed_count, static_cast<unsigned long long>(plan.first_seed));
    if (shard.count > 1) std::printf(", shard %d/%d", shard.index, shard.count);
    std::printf(": %d runs, %d finished before, %d to run on %d thread(s)\n", total, before, to_run,
                std::min(options.jobs, std::max(1, to_run)));
    std::fflush(stdout);
    if (a.quiet || to_run == 0) return;
    Progress::Style style;
    style.bar = true;
    style.per_minute = true;
    style.already_done = before;
    style.heartbeat_s = 60.0;
    progress = std::make_unique<Progress>("batch", "runs", total, style);
    progress->update(before);
  };
  options.on_run = [&](const RunRecord&, int done_now) {
    if (progress) progress->update(finished_before + done_now);
  };
  options.on_redo = [](const std::string& problem) {
    std::fprintf(stderr, "batch: %s; the run is done again\n", problem.c_str());
  };
  const BatchRunResult result = run_batch(plan, field, store, options);
  if (progress) progress->finish();

  write_batch_report(a.out, manifest, result.records);
  print_summary(result.records);
  std::printf(
      "wrote %s/runs.csv, timings.csv, report.json, report.md, plots/ (%d runs: %d now, "
      "%d before)\n",
      a.out.c_str(), total, result.ran, result.finished_before);
}

void run_merge_command(const MergeArgs& a) {
  namespace fs = std::filesystem;
  // The inputs: batch folders, none of them the output.
  std::vector<BatchStore> shards;
  for (const std::string& dir : a.dirs) {
    std::error_code ec;
    if (fs::exists(a.out, ec) && fs::equivalent(dir, a.out, ec)) {
      throw UsageError("--out must be a folder of its own, not the input " + dir);
    }
    shards.push_back(BatchStore::open_existing(dir));
  }

  // They must be the shards of one batch, every shard exactly once.
  const BatchManifest& first = shards.front().manifest();
  const int count = first.shard.count;
  std::vector<const BatchStore*> by_index(count, nullptr);
  for (const BatchStore& s : shards) {
    const std::string diff = s.manifest().difference(first, /*ignore_shard=*/true);
    if (!diff.empty()) {
      throw InputError(s.dir() + ": not a shard of the batch in " + shards.front().dir() + " (" +
                       diff + ")");
    }
    if (s.manifest().shard.count != count) {
      throw InputError(s.dir() + ": shard of " + std::to_string(s.manifest().shard.count) +
                       ", but " + shards.front().dir() + " is a shard of " + std::to_string(count));
    }
    const BatchStore*& slot = by_index[s.manifest().shard.index];
    if (slot) {
      throw InputError(s.dir() + ": holds shard " + std::to_string(s.manifest().shard.index) + "/" +
                       std::to_string(count) + " as " + slot->dir() + " does");
    }
    slot = &s;
  }
  for (int i = 0; i < count; ++i) {
    if (!by_index[i]) {
      throw InputError("shard " + std::to_string(i) + "/" + std::to_string(count) +
                       " is missing: give the folders of all " + std::to_string(count) + " shards");
    }
  }

  // Every run of every shard must have finished.
  std::vector<std::pair<const BatchStore*, RunRecord>> runs;
  for (const BatchStore* s : by_index) {
    int missing = 0;
    std::string example;
    for (const RunKey& key : s->manifest().shard_runs()) {
      std::optional<RunRecord> r = s->load(key);
      if (r) {
        runs.emplace_back(s, std::move(*r));
      } else if (missing++ == 0) {
        example = key.label();
      }
    }
    if (missing > 0) {
      throw InputError(s->dir() + ": shard " + std::to_string(s->manifest().shard.index) + "/" +
                       std::to_string(count) + " has " + std::to_string(missing) +
                       " unfinished run(s) (" + example +
                       " first); run it again with the same arguments, it resumes");
    }
  }

  // The whole batch in --out: its manifest, every run's files, the report.
  BatchManifest whole = first;
  whole.shard = Shard{};
  const BatchStore out(a.out, whole);
  std::vector<RunRecord> records;
  for (const auto& [from, record] : runs) {
    out.copy_run(*from, record.key);
    records.push_back(record);
  }
  write_batch_report(a.out, whole, records);
  if (!a.quiet) print_summary(records);
  std::printf(
      "merged %d shard(s), %zu runs: wrote %s/runs.csv, timings.csv, report.json, "
      "report.md, plots/\n",
      count, records.size(), a.out.c_str());
}

}  // namespace

void add_batch_command(CLI::App& app) {
  auto args = std::make_shared<BatchArgs>();
  CLI::App* sub = app.add_subcommand(
      "batch",
      "Run every scenario x seed in closed loop (as 'airtwin run' does one), twins in parallel\n"
      "threads. Writes DIR/runs/<scenario>/seed-<n>.json as each run finishes, then\n"
      "DIR/runs.csv (a row per run, sorted by scenario and seed), DIR/timings.csv, and\n"
      "DIR/report.json, DIR/report.md and DIR/plots/ (success rate, completion time and error\n"
      "distributions per scenario). Resumable: started again with the same arguments after being\n"
      "killed, it runs only what had not finished; other arguments in the same DIR are refused.\n"
      "A run's result depends on its scenario, seed and the flags only, not on --jobs.\n"
      "On a cluster: --shard I/N per array task, then 'airtwin batch-merge'. docs/batch.md.");
  sub->add_option("scenarios", args->scenarios, "Scenario files (YAML, distinct names)")
      ->required();
  sub->add_option("--seeds", args->seeds, "Seeds per scenario: --first-seed, --first-seed + 1, ...")
      ->required();
  sub->add_option("--first-seed", args->first_seed, "The first seed")->capture_default_str();
  sub->add_option("--jobs", args->jobs,
                  "Runs in parallel (threads); 0: one per usable core (" +
                      std::to_string(usable_cpus()) + " here)")
      ->capture_default_str();
  sub->add_option("--shard", args->shard,
                  "Run only shard I of N (0-based: 0 <= I < N), every N-th run from the I-th;\n"
                  "with Slurm: --shard $SLURM_ARRAY_TASK_ID/N for --array=0-(N-1)")
      ->capture_default_str();
  sub->add_option("--out", args->out, "Output folder (new, empty, or this batch's)")->required();
  sub->add_flag("--logs", args->logs,
                "Keep each run's log.csv, decisions.csv and plans.csv beside its record (MBs per "
                "run)");
  add_run_setup_flags(sub, args->setup,
                      "calibrate the twin's camera once into DIR/calibration and DIR/calib.yaml");
  sub->add_flag("--quiet", args->quiet, "No progress display");
  sub->callback([args] { run_batch_command(*args); });
}

void add_batch_merge_command(CLI::App& app) {
  auto args = std::make_shared<MergeArgs>();
  CLI::App* sub = app.add_subcommand(
      "batch-merge",
      "Merge the folders of a batch's shards ('airtwin batch --shard I/N', every I once, all\n"
      "finished) into one folder: the runs, runs.csv, timings.csv and the report of the whole\n"
      "batch, the same as one unsharded 'airtwin batch' would write. docs/batch.md.");
  sub->add_option("dirs", args->dirs, "The shards' output folders")->required();
  sub->add_option("--out", args->out, "Output folder (new, empty, or this batch's)")->required();
  sub->add_flag("--quiet", args->quiet, "No per-scenario summary");
  sub->callback([args] { run_merge_command(*args); });
}

}  // namespace airtwin::cli
