#include "runs/batch_runner.h"

#include <algorithm>
#include <chrono>
#include <mutex>
#include <optional>

#include "common/errors.h"
#include "common/parallel_for.h"
#include "models/nozzle_log.h"
#include "models/trajectory_data.h"
#include "sim/mujoco_runtime.h"

namespace airtwin {
namespace {

// One run, committed: the twin's failure is a result, anything else propagates.
RunRecord run_and_commit(const BatchPlan& plan, const AirFieldModel& field, const BatchStore& store,
                         const BatchRunOptions& options, const RunKey& key) {
  const Scenario& scenario = plan.scenario(key.scenario).scenario;
  ScenarioRunOptions run_options = options.run;
  run_options.seed = key.seed;
  run_options.on_frame = nullptr;
  run_options.on_progress = nullptr;
  const double time_limit_s = scenario.task.time_limit_s;

  const auto start = std::chrono::steady_clock::now();
  const auto wall_s = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  std::string json;
  std::optional<RunLogs> logs;
  try {
    const ScenarioRunResult result = run_scenario(scenario, field, run_options);
    json = record_json(result, time_limit_s, wall_s());
    if (options.keep_logs) {
      logs = RunLogs{trajectory_csv(result.log), decisions_csv(result), plans_csv(result),
                     nozzle_log_csv(result.nozzle_log), result.vision_detections_csv};
    }
  } catch (const SimulationError& e) {
    json = failed_record_json(key, static_cast<int>(scenario.scene.objects.size()), time_limit_s,
                              run_options.vision_camera ? "vision" : "truth", e.what(), wall_s());
  }
  store.commit(key, json, logs ? &*logs : nullptr);
  return parse_record(json, store.record_path(key));
}

}  // namespace

BatchRunResult run_batch(const BatchPlan& plan, const AirFieldModel& field, const BatchStore& store,
                         const BatchRunOptions& options) {
  AIRTWIN_DEMAND(options.jobs >= 1);
  const std::vector<RunKey> runs = plan.shard_runs();

  // What the folder already holds; unreadable records are redone.
  std::vector<std::optional<RunRecord>> records(runs.size());
  std::vector<size_t> pending;
  for (size_t i = 0; i < runs.size(); ++i) {
    std::string problem;
    records[i] = store.load(runs[i], &problem);
    if (records[i]) continue;
    if (!problem.empty() && options.on_redo) options.on_redo(problem);
    pending.push_back(i);
  }
  BatchRunResult result;
  result.finished_before = static_cast<int>(runs.size() - pending.size());

  // Hand runs out seed by seed across the scenarios, so that the rate seen early on (progress,
  // time left) mixes cheap and costly scenarios as the whole batch does.
  std::stable_sort(pending.begin(), pending.end(),
                   [&](size_t a, size_t b) { return runs[a].seed < runs[b].seed; });
  if (options.on_start) options.on_start(result.finished_before, static_cast<int>(pending.size()));

  // The pool: the pending runs on the workers, each committed as soon as it finished.
  std::mutex mutex;  // guards records, done and the callback
  int done = 0;
  parallel_for(pending.size(), options.jobs, [&](size_t n) {
    const size_t i = pending[n];
    RunRecord record = run_and_commit(plan, field, store, options, runs[i]);
    const std::lock_guard lock(mutex);
    ++done;
    if (options.on_run) options.on_run(record, done);
    records[i] = std::move(record);
  });

  result.ran = done;
  for (std::optional<RunRecord>& r : records) {
    AIRTWIN_DEMAND(r.has_value());
    result.records.push_back(std::move(*r));
  }
  return result;
}

}  // namespace airtwin
