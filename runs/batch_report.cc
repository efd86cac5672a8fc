#include "runs/batch_report.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>

#include <nlohmann/json.hpp>

#include "common/atomic_file.h"
#include "common/errors.h"
#include "common/quantile.h"
#include "controller/run_metrics.h"
#include "plots/batch_plot.h"
#include "sim/object_physics.h"
#include "sim/scene_builder.h"

namespace airtwin {

using nlohmann::ordered_json;

namespace {

// printf into a std::string.
std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* fmt, ...) {
  char buffer[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buffer, sizeof buffer, fmt, args);
  va_end(args);
  return buffer;
}

void sort_records(std::vector<RunRecord>& records) {
  std::sort(records.begin(), records.end(),
            [](const RunRecord& a, const RunRecord& b) { return a.key < b.key; });
}

// The records grouped by scenario, each group in seed order, groups in name order.
std::map<std::string, std::vector<const RunRecord*>> by_scenario(
    const std::vector<RunRecord>& records) {
  std::map<std::string, std::vector<const RunRecord*>> groups;
  for (const RunRecord& r : records) groups[r.key.scenario].push_back(&r);
  for (auto& [name, runs] : groups) {
    std::sort(runs.begin(), runs.end(),
              [](const RunRecord* a, const RunRecord* b) { return a->key.seed < b->key.seed; });
  }
  return groups;
}

// The distribution of `figure` over the runs `keep` accepts (value unset: skipped).
Distribution distribution_of(const std::vector<const RunRecord*>& runs,
                             const std::function<bool(const RunRecord&)>& keep,
                             const std::function<std::optional<double>(const RunRecord&)>& figure,
                             bool higher_is_better = false) {
  std::vector<double> values;
  std::vector<uint64_t> seeds;
  for (const RunRecord* r : runs) {
    if (!keep(*r)) continue;
    const std::optional<double> v = figure(*r);
    if (!v) continue;
    values.push_back(*v);
    seeds.push_back(r->key.seed);
  }
  return distribution(values, seeds, higher_is_better);
}

bool twin_completed(const RunRecord& r) { return r.error.empty(); }
bool succeeded(const RunRecord& r) { return r.success; }

// 95% Wilson score interval of a success proportion.
std::pair<double, double> wilson95(int successes, int n) {
  if (n == 0) return {0.0, 0.0};
  constexpr double z = 1.959963984540054;
  const double p = static_cast<double>(successes) / n, z2 = z * z;
  const double denominator = 1.0 + z2 / n;
  const double centre = (p + z2 / (2.0 * n)) / denominator;
  const double half = z * std::sqrt(p * (1.0 - p) / n + z2 / (4.0 * n * n)) / denominator;
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

// A CSV cell for an optional number.
std::string cell(const std::optional<double>& v, const char* fmt) {
  return v ? format(fmt, *v) : std::string();
}

// Free text in one CSV cell: no separators, no line breaks.
std::string plain_cell(std::string text) {
  for (char& c : text) {
    if (c == ',' || c == '\n' || c == '\r' || c == '"') c = ';';
  }
  return text;
}

ordered_json distribution_json(const Distribution& d) {
  if (d.count == 0) return nullptr;
  return {{"count", d.count}, {"mean", d.mean},   {"median", d.median},
          {"p90", d.p90},     {"worst", d.worst}, {"worst_seed", d.worst_seed}};
}

std::string seed_list(const std::vector<uint64_t>& seeds, size_t at_most) {
  std::string out;
  for (size_t i = 0; i < seeds.size() && i < at_most; ++i) {
    out += (i ? ", " : "") + std::to_string(seeds[i]);
  }
  if (seeds.size() > at_most) out += format(" and %zu more", seeds.size() - at_most);
  return out.empty() ? "-" : out;
}

// "median | p90 | worst (seed s)" cells of a Markdown table, `digits` decimals.
std::string md_cells(const Distribution& d, int digits) {
  if (d.count == 0) return "- | - | -";
  return format("%.*f | %.*f | %.*f (seed %llu)", digits, d.median, digits, d.p90, digits, d.worst,
                static_cast<unsigned long long>(d.worst_seed));
}

// ---- Timing (wall clock) --------------------------------------------------------------------

struct TimingStats {
  std::string scenario;
  Distribution wall_s, decision_ms_mean, decision_ms_max, vision_frame_ms;
};

std::vector<TimingStats> timing_stats(const std::vector<RunRecord>& records) {
  std::vector<TimingStats> out;
  const auto all = [](const RunRecord&) { return true; };
  for (const auto& [name, runs] : by_scenario(records)) {
    TimingStats t;
    t.scenario = name;
    t.wall_s = distribution_of(runs, all, [](const RunRecord& r) { return r.wall_s; });
    t.decision_ms_mean = distribution_of(runs, twin_completed,
                                         [](const RunRecord& r) { return r.decision_ms_mean; });
    t.decision_ms_max =
        distribution_of(runs, twin_completed, [](const RunRecord& r) { return r.decision_ms_max; });
    t.vision_frame_ms = distribution_of(
        runs, [](const RunRecord& r) { return r.perception == "vision" && r.vision_frames > 0; },
        [](const RunRecord& r) { return r.vision_frame_ms; });
    out.push_back(std::move(t));
  }
  return out;
}

// ---- report.json ----------------------------------------------------------------------------

ordered_json batch_json(const BatchManifest& manifest, size_t runs) {
  ordered_json j = manifest.identity(/*with_shard=*/false);
  if (manifest.shard.count > 1) {
    j["shard"] = format("%d/%d", manifest.shard.index, manifest.shard.count);
  }
  j["runs"] = runs;
  return j;
}

std::string report_json(const BatchManifest& manifest, const std::vector<RunRecord>& records,
                        const std::vector<ScenarioStats>& stats,
                        const std::vector<PhysicsSensitivity>& sensitivity,
                        const std::vector<std::string>& plots) {
  ordered_json j;
  j["batch"] = batch_json(manifest, records.size());
  j["scenarios"] = ordered_json::array();
  for (const ScenarioStats& s : stats) {
    ordered_json e;
    e["scenario"] = s.scenario;
    e["runs"] = s.runs;
    e["successes"] = s.successes;
    e["success_rate"] = s.success_rate;
    e["success_rate_ci95"] = {s.success_ci95_low, s.success_ci95_high};
    e["failed_seeds"] = s.failed_seeds;
    e["twin_failure_seeds"] = s.twin_failure_seeds;
    e["stalled_seeds"] = s.stalled_seeds;
    e["completion_time_s"] = distribution_json(s.completion_time_s);
    e["path_error_mean_cm"] =
        s.path_error_mean_cm ? distribution_json(*s.path_error_mean_cm) : ordered_json(nullptr);
    e["path_error_max_cm"] =
        s.path_error_max_cm ? distribution_json(*s.path_error_max_cm) : ordered_json(nullptr);
    e["max_pairwise_distance_cm"] = distribution_json(s.max_pairwise_distance_cm);
    e["objects_in_zone_fraction"] = distribution_json(s.objects_in_zone_fraction);
    e["decisions"] = distribution_json(s.decisions);
    j["scenarios"].push_back(std::move(e));
  }
  if (!sensitivity.empty()) {
    j["physics_variation"] = manifest.settings.value("physics_variation", std::string());
    j["object_physics"] = ordered_json::array();
    for (const PhysicsSensitivity& e : sensitivity) {
      j["object_physics"].push_back({{"scenario", e.scenario},
                                     {"type", e.type},
                                     {"key", e.key},
                                     {"successful_runs", distribution_json(e.successes)},
                                     {"failed_runs", distribution_json(e.failures)}});
    }
  }
  j["plots"] = plots;
  // Wall clock last, apart from the results.
  ordered_json timing;
  double total_s = 0.0;
  for (const RunRecord& r : records) total_s += r.wall_s;
  timing["note"] = "wall clock of the machine(s) that ran the runs; not part of the results";
  timing["run_wall_s_total"] = total_s;
  timing["scenarios"] = ordered_json::array();
  for (const TimingStats& t : timing_stats(records)) {
    timing["scenarios"].push_back({{"scenario", t.scenario},
                                   {"run_wall_s", distribution_json(t.wall_s)},
                                   {"decision_ms_mean", distribution_json(t.decision_ms_mean)},
                                   {"decision_ms_max", distribution_json(t.decision_ms_max)},
                                   {"vision_frame_ms", distribution_json(t.vision_frame_ms)}});
  }
  j["timing"] = std::move(timing);
  return j.dump(2) + "\n";
}

// ---- report.md ------------------------------------------------------------------------------

std::string report_md(const BatchManifest& manifest, const std::vector<RunRecord>& records,
                      const std::vector<ScenarioStats>& stats,
                      const std::vector<PhysicsSensitivity>& sensitivity,
                      const std::vector<std::string>& plots) {
  std::string md = "# Batch report\n\n";
  // What was run.
  std::string names;
  for (const BatchManifest::Entry& e : manifest.scenarios) {
    names += (names.empty() ? "" : ", ") + e.name;
  }
  const uint64_t last_seed = manifest.first_seed + static_cast<uint64_t>(manifest.seed_count) - 1;
  const std::string perception = manifest.settings.value("perception", std::string("truth"));
  md += format("Scenarios %s; seeds %llu-%llu; %zu runs", names.c_str(),
               static_cast<unsigned long long>(manifest.first_seed),
               static_cast<unsigned long long>(last_seed), records.size());
  if (manifest.shard.count > 1) {
    md += format(" (shard %d/%d of the batch)", manifest.shard.index, manifest.shard.count);
  }
  md += "; perception " + perception + ".\n";
  md +=
      "Every run: `runs.csv`; these figures as JSON: `report.json`; the batch's arguments: "
      "`batch.json`.\nMedian and p90 interpolate between runs (numpy's default); worst: the "
      "largest value and its seed.\n\n";

  md +=
      "## Success\n\n| scenario | runs | success | 95% interval (Wilson) | failed seeds | of "
      "them stalled |\n|---|---|---|---|---|---|\n";
  for (const ScenarioStats& s : stats) {
    md += format("| %s | %d | %.0f%% (%d/%d) | %.0f-%.0f%% | %s | %s |\n", s.scenario.c_str(),
                 s.runs, 100.0 * s.success_rate, s.successes, s.runs, 100.0 * s.success_ci95_low,
                 100.0 * s.success_ci95_high, seed_list(s.failed_seeds, 20).c_str(),
                 seed_list(s.stalled_seeds, 20).c_str());
  }
  md += format(
      "\nStalled: a failed run whose objects moved no more than %.0f cm over its last %.0f s (the "
      "controller's pushes moved nothing), not one cut short while progressing.\n",
      100.0 * kStillDistance_m, kStalledSpan_s);
  md +=
      "\n## Completion time (s, successful runs)\n\n"
      "| scenario | median | p90 | worst (seed) | mean |\n|---|---|---|---|---|\n";
  for (const ScenarioStats& s : stats) {
    md += "| " + s.scenario + " | " + md_cells(s.completion_time_s, 1) + " | " +
          (s.completion_time_s.count ? format("%.1f", s.completion_time_s.mean) : "-") + " |\n";
  }
  bool any_path = false;
  for (const ScenarioStats& s : stats) any_path = any_path || s.path_error_mean_cm.has_value();
  if (any_path) {
    md +=
        "\n## Path error (cm, distance to the reference path; every run the twin completed)\n\n"
        "| scenario | mean error: median | p90 | worst (seed) | max error: median | p90 | "
        "worst (seed) |\n|---|---|---|---|---|---|---|\n";
    for (const ScenarioStats& s : stats) {
      if (!s.path_error_mean_cm) continue;
      md += "| " + s.scenario + " | " + md_cells(*s.path_error_mean_cm, 2) + " | " +
            md_cells(*s.path_error_max_cm, 2) + " |\n";
    }
  }
  md +=
      "\n## Objects (every run the twin completed)\n\n"
      "| scenario | max pairwise distance (cm): median | p90 | worst (seed) | in zone at the end: "
      "median | p90 | worst (seed) | decisions: median |\n|---|---|---|---|---|---|---|---|\n";
  for (const ScenarioStats& s : stats) {
    md += "| " + s.scenario + " | " + md_cells(s.max_pairwise_distance_cm, 1) + " | " +
          md_cells(s.objects_in_zone_fraction, 2) + " | " +
          (s.decisions.count ? format("%.0f", s.decisions.median) : "-") + " |\n";
  }
  bool any_failure = false;
  for (const ScenarioStats& s : stats) any_failure = any_failure || !s.twin_failure_seeds.empty();
  if (any_failure) {
    md += "\n## Twin failures (the simulation diverged; counted as failed runs)\n\n";
    for (const RunRecord& r : records) {
      if (!r.error.empty()) md += "- " + r.key.label() + ": " + r.error + "\n";
    }
  }
  if (!sensitivity.empty()) {
    md += "\n## Objects that differ (`--vary-physics " +
          manifest.settings.value("physics_variation", std::string()) +
          "`)\n\nEach drawn parameter over the objects of the successful runs and over those of "
          "the failed runs (typed units, sim/object_physics.h); where the two part, the "
          "controller is sensitive to it.\n\n| scenario | type | key | successful runs: "
          "median | mean | objects | failed runs: median | mean | objects |\n"
          "|---|---|---|---|---|---|---|---|---|\n";
    for (const PhysicsSensitivity& e : sensitivity) {
      const auto cells = [](const Distribution& d) {
        return d.count ? format("%.4g | %.4g | %d", d.median, d.mean, d.count)
                       : std::string("- | - | 0");
      };
      md += "| " + e.scenario + " | " + e.type + " | " + e.key + " | " + cells(e.successes) +
            " | " + cells(e.failures) + " |\n";
    }
  }
  md += "\n## Plots\n\n";
  for (const std::string& p : plots) md += "![" + p + "](" + p + ")\n";

  md +=
      "\n## Timing\n\nWall clock of the machine(s) that ran the runs: not part of the results, "
      "and different on every run of the batch.\n\n"
      "| scenario | run (s): median | p90 | longest (seed) | decision (ms, run means): median "
      "| p90 | worst (seed) | vision (ms per frame): median |\n|---|---|---|---|---|---|---|---|\n";
  for (const TimingStats& t : timing_stats(records)) {
    md += "| " + t.scenario + " | " + md_cells(t.wall_s, 2) + " | " +
          md_cells(t.decision_ms_mean, 2) + " | " +
          (t.vision_frame_ms.count ? format("%.1f", t.vision_frame_ms.median) : "-") + " |\n";
  }
  return md;
}

// ---- Plots ----------------------------------------------------------------------------------

std::vector<std::string> write_plots(const std::string& dir, const std::vector<RunRecord>& records,
                                     const std::vector<ScenarioStats>& stats) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir + "/plots", ec);
  if (ec) throw InputError(dir + "/plots: cannot create the folder: " + ec.message());
  const auto groups = by_scenario(records);
  const auto values = [&](const std::string& scenario,
                          const std::function<bool(const RunRecord&)>& keep,
                          const std::function<std::optional<double>(const RunRecord&)>& figure) {
    std::vector<double> out;
    for (const RunRecord* r : groups.at(scenario)) {
      if (!keep(*r)) continue;
      if (const auto v = figure(*r)) out.push_back(*v);
    }
    return out;
  };
  const auto time_of = [](const RunRecord& r) { return r.completion_time_s; };
  const auto mean_error = [](const RunRecord& r) { return r.path_error_mean_cm; };
  const auto max_error = [](const RunRecord& r) { return r.path_error_max_cm; };
  const auto pairwise = [](const RunRecord& r) {
    return std::optional<double>(r.max_pairwise_distance_cm);
  };

  std::vector<std::string> written;
  // Box plots over the scenarios.
  std::vector<plots::BoxGroup> times, means, maxes;
  for (const ScenarioStats& s : stats) {
    times.push_back({s.scenario, format("%d/%d done", s.successes, s.runs),
                     values(s.scenario, succeeded, time_of)});
    if (!s.path_error_mean_cm) continue;
    const std::string n = format("%d runs", s.path_error_mean_cm->count);
    means.push_back({s.scenario, n, values(s.scenario, twin_completed, mean_error)});
    maxes.push_back({s.scenario, n, values(s.scenario, twin_completed, max_error)});
  }
  plots::write_box_plot_png("Completion time of the successful runs", "completion time (s)", times,
                            dir + "/plots/completion_time.png");
  written.push_back("plots/completion_time.png");
  if (!means.empty()) {
    plots::write_box_plot_png("Mean distance to the path, per run", "mean path error (cm)", means,
                              dir + "/plots/path_error_mean.png");
    plots::write_box_plot_png("Largest distance to the path, per run", "max path error (cm)", maxes,
                              dir + "/plots/path_error_max.png");
    written.push_back("plots/path_error_mean.png");
    written.push_back("plots/path_error_max.png");
  }
  // One picture per scenario: completion times, and the path error or the objects' spread.
  for (const ScenarioStats& s : stats) {
    std::vector<plots::HistogramPanel> panels;
    const int not_done = s.runs - s.successes;
    panels.push_back({"completion time", "completion time (s)",
                      not_done ? format("%d run(s) not done in time are not shown", not_done)
                               : std::string("every run done"),
                      values(s.scenario, succeeded, time_of)});
    if (s.path_error_max_cm) {
      panels.push_back({"largest distance to the path", "max path error (cm)",
                        format("%d runs", s.path_error_max_cm->count),
                        values(s.scenario, twin_completed, max_error)});
    } else {
      panels.push_back({"largest distance between objects", "max pairwise distance (cm)",
                        format("%d runs", s.max_pairwise_distance_cm.count),
                        values(s.scenario, twin_completed, pairwise)});
    }
    const std::string file = "plots/" + s.scenario + ".png";
    plots::write_histograms_png(s.scenario + format(": %d runs", s.runs), panels, dir + "/" + file);
    written.push_back(file);
  }
  return written;
}

}  // namespace

Distribution distribution(const std::vector<double>& values, const std::vector<uint64_t>& seeds,
                          bool higher_is_better) {
  AIRTWIN_DEMAND(values.size() == seeds.size());
  Distribution d;
  d.count = static_cast<int>(values.size());
  if (values.empty()) return d;
  // The worst value and the smallest seed that has it.
  size_t worst = 0;
  double sum = 0.0;
  for (size_t i = 0; i < values.size(); ++i) {
    sum += values[i];
    const bool worse = higher_is_better ? values[i] < values[worst] : values[i] > values[worst];
    if (worse || (values[i] == values[worst] && seeds[i] < seeds[worst])) worst = i;
  }
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  d.mean = sum / static_cast<double>(values.size());
  d.median = quantile_of_sorted(sorted, 0.5);
  d.p90 = quantile_of_sorted(sorted, higher_is_better ? 0.1 : 0.9);
  d.worst = values[worst];
  d.worst_seed = seeds[worst];
  return d;
}

bool stalled(const RunRecord& record) {
  return record.error.empty() && record.still_since_s.has_value() &&
         run_stalled(record.success, record.end_time_s, *record.still_since_s);
}

std::vector<ScenarioStats> scenario_stats(const std::vector<RunRecord>& records) {
  std::vector<ScenarioStats> out;
  const auto all = [](const RunRecord&) { return true; };
  for (const auto& [name, runs] : by_scenario(records)) {
    ScenarioStats s;
    s.scenario = name;
    s.runs = static_cast<int>(runs.size());
    bool path_task = false;
    for (const RunRecord* r : runs) {
      s.successes += r->success ? 1 : 0;
      if (!r->success) s.failed_seeds.push_back(r->key.seed);
      if (!r->error.empty()) s.twin_failure_seeds.push_back(r->key.seed);
      if (stalled(*r)) s.stalled_seeds.push_back(r->key.seed);
      path_task = path_task || r->path_error_mean_cm.has_value();
    }
    s.success_rate = s.runs ? static_cast<double>(s.successes) / s.runs : 0.0;
    std::tie(s.success_ci95_low, s.success_ci95_high) = wilson95(s.successes, s.runs);
    s.completion_time_s =
        distribution_of(runs, succeeded, [](const RunRecord& r) { return r.completion_time_s; });
    if (path_task) {
      s.path_error_mean_cm = distribution_of(
          runs, twin_completed, [](const RunRecord& r) { return r.path_error_mean_cm; });
      s.path_error_max_cm = distribution_of(runs, twin_completed,
                                            [](const RunRecord& r) { return r.path_error_max_cm; });
    }
    s.max_pairwise_distance_cm = distribution_of(
        runs, twin_completed, [](const RunRecord& r) { return r.max_pairwise_distance_cm; });
    s.objects_in_zone_fraction = distribution_of(
        runs, twin_completed,
        [](const RunRecord& r) -> std::optional<double> {
          if (r.n_objects <= 0) return std::nullopt;
          return static_cast<double>(r.objects_in_zone) / r.n_objects;
        },
        /*higher_is_better=*/true);
    s.decisions = distribution_of(runs, all, [](const RunRecord& r) {
      return std::optional<double>(static_cast<double>(r.decisions));
    });
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<PhysicsSensitivity> physics_sensitivity(const std::vector<RunRecord>& records) {
  std::vector<PhysicsSensitivity> out;
  for (const auto& [name, runs] : by_scenario(records)) {
    // (type, key) -> values and seeds over the successful runs' objects [0] and the failed [1].
    struct Values {
      std::vector<double> values[2];
      std::vector<uint64_t> seeds[2];
    };
    std::map<std::pair<std::string, size_t>, Values> table;
    for (const RunRecord* r : runs) {
      if (!r->error.empty()) continue;  // a twin failure says nothing of the controller
      for (const auto& o : r->object_physics) {
        // The record's text through the parser people type it with (sim/object_physics.h).
        SceneParameters scene;
        apply_drag_law("physical", &scene);
        const std::string type = o.physics.substr(0, o.physics.find(':'));
        try {
          apply_object_physics(o.physics, &scene);
        } catch (const InputError& e) {
          throw InputError(r->key.label() + ": object '" + o.id + "': " + e.what());
        }
        const ObjectTypeParameters& p = scene.of(parse_object_type(type, r->key.label()));
        for (const ObjectPhysicsSpec& spec : object_physics_catalogue()) {
          if (o.physics.find(std::string(spec.key) + '=') == std::string::npos) continue;
          Values& v = table[{type, static_cast<size_t>(spec.id)}];
          const int side = r->success ? 0 : 1;
          v.values[side].push_back(object_physics_value(p, spec.id));
          v.seeds[side].push_back(r->key.seed);
        }
      }
    }
    for (const auto& [type_key, v] : table) {
      double lo = INFINITY, hi = -INFINITY;
      for (const auto& side : v.values) {
        for (double x : side) {
          lo = std::min(lo, x);
          hi = std::max(hi, x);
        }
      }
      if (!(hi > lo)) continue;  // not varied (the area, or a single value)
      PhysicsSensitivity e;
      e.scenario = name;
      e.type = type_key.first;
      e.key = object_physics_catalogue()[type_key.second].key;
      e.successes = distribution(v.values[0], v.seeds[0]);
      e.failures = distribution(v.values[1], v.seeds[1]);
      out.push_back(std::move(e));
    }
  }
  return out;
}

std::string runs_csv(std::vector<RunRecord> records) {
  sort_records(records);
  std::string csv =
      "scenario,seed,success,completion_time_s,path_error_mean_cm,path_error_std_cm,"
      "path_error_max_cm,max_pairwise_distance_cm,objects_in_zone,n_objects,decisions,end_time_s,"
      "time_limit_s,still_since_s,perception,vision_frames,vision_detections,vision_tracks,"
      "vision_missed,vision_merged,vision_lost,vision_left_view,error\n";
  for (const RunRecord& r : records) {
    csv += r.key.scenario + "," + std::to_string(r.key.seed) + "," + (r.success ? "1" : "0") + "," +
           cell(r.completion_time_s, "%.3f") + "," + cell(r.path_error_mean_cm, "%.4f") + "," +
           cell(r.path_error_std_cm, "%.4f") + "," + cell(r.path_error_max_cm, "%.4f") +
           format(",%.4f,%d,%d,%lld,%.3f,%.3f,", r.max_pairwise_distance_cm, r.objects_in_zone,
                  r.n_objects, static_cast<long long>(r.decisions), r.end_time_s, r.time_limit_s) +
           cell(r.still_since_s, "%.3f") + "," + r.perception + ",";
    if (r.perception == "vision") {
      csv += format(
          "%lld,%lld,%lld,%lld,%lld,%lld,%lld,", static_cast<long long>(r.vision_frames),
          static_cast<long long>(r.vision_detections), static_cast<long long>(r.vision_tracks),
          static_cast<long long>(r.vision_missed), static_cast<long long>(r.vision_merged),
          static_cast<long long>(r.vision_lost), static_cast<long long>(r.vision_left_view));
    } else {
      csv += ",,,,,,,";
    }
    csv += plain_cell(r.error) + "\n";
  }
  return csv;
}

std::string timings_csv(std::vector<RunRecord> records) {
  sort_records(records);
  std::string csv = "scenario,seed,wall_s,decision_ms_mean,decision_ms_max,vision_frame_ms\n";
  for (const RunRecord& r : records) {
    csv += r.key.scenario + "," + std::to_string(r.key.seed) +
           format(",%.3f,%.4f,%.4f,", r.wall_s, r.decision_ms_mean, r.decision_ms_max) +
           (r.perception == "vision" ? format("%.3f", r.vision_frame_ms) : std::string()) + "\n";
  }
  return csv;
}

void write_batch_report(const std::string& dir, const BatchManifest& manifest,
                        const std::vector<RunRecord>& unsorted) {
  std::vector<RunRecord> records = unsorted;
  sort_records(records);
  const std::vector<ScenarioStats> stats = scenario_stats(records);
  const std::vector<std::string> plots = write_plots(dir, records, stats);
  write_file_atomically(dir + "/runs.csv", runs_csv(records));
  write_file_atomically(dir + "/timings.csv", timings_csv(records));
  const std::vector<PhysicsSensitivity> sensitivity = physics_sensitivity(records);
  write_file_atomically(dir + "/report.json",
                        report_json(manifest, records, stats, sensitivity, plots));
  write_file_atomically(dir + "/report.md",
                        report_md(manifest, records, stats, sensitivity, plots));
}

}  // namespace airtwin
