// airtwin region: the feasible manipulation region (runs/manipulation_region.h) by the model the
// controller plans with and, with --twin, by the twin: which pushes of the paper's line search
// move an object at rest, over a grid of the floor and every direction.

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/cli_common.h"
#include "app/commands.h"
#include "app/progress.h"
#include "app/run_setup.h"
#include "common/csv.h"
#include "common/errors.h"
#include "runs/manipulation_region.h"
#include "scenes/scenario.h"

namespace airtwin::cli {
namespace {

struct RegionArgs {
  RegionOptions options;
  std::string scenario;
  RunSetupFlags setup;
  bool twin = false;
  bool quiet = false;
  std::string out;
  std::string trajectories_out;
};

constexpr std::initializer_list<FlagOf> kRegionFlags = {{"region.object", "--object"},
                                                        {"region.extent_m", "--extent"},
                                                        {"region.step_m", "--step"},
                                                        {"region.directions", "--directions"},
                                                        {"region.distance_m", "--distance"},
                                                        {"region.horizon_s", "--horizon"},
                                                        {"region.min_travel_m", "--min-travel"},
                                                        {"region.settle_s", "--settle"},
                                                        {"region.threads", "--threads"}};

void print_judgement(const char* judge, const RegionJudgement& j, int points) {
  std::printf("%-6s moved %4d of %4d pushes;", judge, j.all.moved, j.all.of);
  for (const PushClassInfo& c : kPushClasses) {
    const RegionTally& t = j.by_class[static_cast<size_t>(c.id)];
    std::printf(" %s %d/%d", c.name, t.moved, t.of);
  }
  std::printf("; every direction at %d of %d points\n", j.region_points, points);
}

void run_region(const RegionArgs& a, const CLI::App& sub) {
  RegionOptions o = a.options;
  // A scenario's controller sets D and Delta T, and its first object the type, unless the flags
  // say otherwise; its task is drawn over the maps.
  std::optional<Scenario> scenario;
  if (!a.scenario.empty()) {
    scenario = read_scenario(a.scenario);
    // A plane search's mu0 is a point, not a distance behind the object: D stays the flag's.
    if (sub.count("--distance") == 0 && scenario->controller.search == CemSearch::kLine) {
      o.distance_m = scenario->controller.mean0_m;
    }
    if (sub.count("--horizon") == 0) o.horizon_s = scenario->controller.horizon_s;
    if (sub.count("--object") == 0) o.object = scenario->scene.objects.front().type;
  }
  // What only the twin uses is refused without it rather than ignored.
  if (!a.twin) {
    for (const char* flag : {"--effect", "--object-physics", "--settle", "--seed", "--threads",
                             "--trajectories-out"}) {
      if (sub.count(flag) > 0) throw UsageError(std::string(flag) + " needs --twin");
    }
  }
  with_flags(kRegionFlags, [&] { o.validate(); });
  check_run_setup_flags(a.setup);
  const AirFieldModel field = field_model_of(a.setup);
  const ScenarioRunOptions run = run_options_of(a.setup);
  std::vector<RegionPush> pushes = model_region(o, field, run);
  if (a.twin) {
    std::unique_ptr<Progress> progress;
    int reachable = 0;
    for (const RegionPush& p : pushes) reachable += p.reachable() ? 1 : 0;
    if (!a.quiet) progress = std::make_unique<Progress>("region", "pushes", reachable);
    TrajectorySet records;
    run_region_in_twin(
        &pushes, o, run.twin, field,
        [&](int done, int) {
          if (progress) progress->update(done);
        },
        a.trajectories_out.empty() ? nullptr : &records);
    if (!a.trajectories_out.empty()) {
      ensure_parent_dir(a.trajectories_out);
      write_text_file(a.trajectories_out, trajectory_csv(records));
    }
    if (progress) progress->finish();
  }
  const RegionSummary s = summarize_region(pushes, o);
  std::filesystem::create_directories(a.out);
  write_text_file(a.out + "/region.csv", region_csv(pushes));
  write_text_file(a.out + "/region.json", region_json(s, o));
  write_region_png(pushes, s, o, a.out + "/region.png", scenario ? &*scenario : nullptr);

  std::printf(
      "%s at rest, s %.1f cm behind it, held %.2f s: %d points x %d directions, %d pushes "
      "the nozzle can aim\n",
      o.object.c_str(), 100.0 * o.distance_m, o.horizon_s, s.points, o.directions, s.reachable);
  if (s.model) print_judgement("model", *s.model, s.points);
  if (s.twin) print_judgement("twin", *s.twin, s.points);
  if (s.model && s.twin) {
    std::printf(
        "both moved it %d, the model only %d (deluded), the twin only %d (blind), "
        "neither %d\n",
        s.both, s.model_only, s.twin_only, s.neither);
  }
  std::printf("wrote %s/region.csv, region.json, region.png\n", a.out.c_str());
}

}  // namespace

void add_region_command(CLI::App& app) {
  auto args = std::make_shared<RegionArgs>();
  CLI::App* sub = app.add_subcommand(
      "region",
      "The feasible manipulation region (section V-C): on a grid of the floor, for each of N\n"
      "directions, the paper's line search's push (s a distance D behind an object at rest,\n"
      "held Delta T) and whether it moves the object at least --min-travel along the direction:\n"
      "by the model the controller plans with (its prediction) and, with --twin, by the twin\n"
      "(the object released into that orientation's steady air). Writes DIR/region.csv (a row\n"
      "per push), region.json (counts: all, away from / across / toward the point below the\n"
      "nozzle, the points every direction moves, where the judges disagree) and region.png.\n"
      "docs/controller.md.");
  RegionOptions& o = args->options;
  sub->add_option("--scenario", args->scenario,
                  "A scenario file: its line search's mu0 is D and its horizon Delta T, its\n"
                  "first object's type the object (unless --distance, --horizon, --object say\n"
                  "otherwise), and its path or zones and objects are drawn over the maps");
  sub->add_option("--object", o.object, "tracer | cotton")->capture_default_str();
  sub->add_option("--extent", o.extent_m, "The grid covers [-E, E]^2 (m)")->capture_default_str();
  sub->add_option("--step", o.step_m, "Grid spacing (m)")->capture_default_str();
  sub->add_option("--directions", o.directions, "Push directions per point")->capture_default_str();
  sub->add_option("--distance", o.distance_m,
                  "D: s this far behind the object (m; the paper's mu0 41.8 cm)")
      ->capture_default_str();
  sub->add_option("--horizon", o.horizon_s, "Delta T: how long each push is held (s)")
      ->capture_default_str();
  sub->add_option("--min-travel", o.min_travel_m,
                  "A push moved the object when it went this far along its direction (m)")
      ->capture_default_str();
  sub->add_flag("--twin", args->twin, "Also push every object in the twin");
  sub->add_option("--settle", o.settle_s,
                  "With --twin: seconds the object rests, jet off, before its release")
      ->capture_default_str();
  sub->add_option("--seed", o.seed, "With --twin: seed of each trial's turbulence and shape")
      ->capture_default_str();
  sub->add_option("--threads", o.threads, "With --twin: twins in parallel (0: one per core)")
      ->capture_default_str();
  sub->add_option("--trajectories-out", args->trajectories_out,
                  "With --twin: every push's record at 40 Hz from the release as a trajectory\n"
                  "CSV (id = the push's row in region.csv, from 0), which 'airtwin identify'\n"
                  "and 'airtwin discrepancy' read: data where the controller pushes");
  RunSetupFlags& f = args->setup;
  sub->add_option("--table", f.table,
                  std::string("The controller's air model (and with --air model the twin's); ") +
                      kDefaultFieldModelHelp);
  sub->add_option("--model", f.models,
                  "model.json from 'airtwin identify' or extended_model.json from 'airtwin\n"
                  "discrepancy' (repeatable): the dynamics the controller predicts with\n"
                  "(default: as 'run', the models fitted to the physical twin)");
  sub->add_option("--effect", f.effects,
                  "With --twin: a physical effect switched on in the twin, NAME:k=v,...");
  // --object-physics (add_air_flags) likewise acts on the twin only.
  add_air_flags(sub, f.air);
  sub->add_flag("--quiet", args->quiet, "No progress on stderr");
  sub->add_option("--out", args->out, "Output folder")->required();
  sub->callback([args, sub] { run_region(*args, *sub); });
}

}  // namespace airtwin::cli
