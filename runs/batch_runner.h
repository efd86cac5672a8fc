#pragma once
// Runs a batch's share of runs (runs/batch_plan.h) on this machine: twins in parallel threads (a
// pool of `jobs` workers taking the next unfinished run), each finished run committed to the
// batch folder at once (runs/batch_store.h), runs already finished there skipped. A run's result
// depends on its scenario, the options and its seed only (runs/scenario_run.h), so neither the
// job count nor the order in which runs finish changes any record's result fields.
//
// Failures. A run whose twin fails (SimulationError: divergence, NaN) is a result - the record
// says so and the batch goes on. Anything else (bad input such as a model without the dynamics of
// a scenario's object type, a file that cannot be written) stops the batch: the workers finish the
// run in hand, no new run starts, and the first error is rethrown; what was committed stays.
//
// Threads and rendering (--vision): each run renders through its own OSMesa context, created in
// the worker thread that runs it (renders/offscreen_context.h: one context per thread, creation
// serialised); detection and tracking keep per-run state only. Tested in
// tests/runs/batch_runner_test.cc (vision runs in two threads give the records of one thread).

#include <functional>
#include <vector>

#include "models/air_field.h"
#include "runs/batch_plan.h"
#include "runs/batch_record.h"
#include "runs/batch_store.h"
#include "runs/scenario_run.h"

namespace airtwin {

struct BatchRunOptions {
  /// Worker threads (>= 1); more than the runs left is the runs left.
  int jobs = 1;
  /// Keep each run's log.csv and decisions.csv beside its record.
  bool keep_logs = false;
  /// The options of every run; the seed is each run's, and on_frame / on_progress are not used.
  ScenarioRunOptions run;
  /// Called once before any run: runs finished earlier, runs to do now. From the calling thread.
  std::function<void(int finished_before, int to_run)> on_start;
  /// Called after each run is committed, with its record and the runs done so far in this call;
  /// from one worker at a time.
  std::function<void(const RunRecord& record, int done_now)> on_run;
  /// Called for each record found unreadable and redone (the reason). From the calling thread.
  std::function<void(const std::string& problem)> on_redo;
};

struct BatchRunResult {
  int finished_before = 0;  ///< runs found finished in the folder
  int ran = 0;              ///< runs done in this call
  /// Every run of the shard, in (scenario, seed) order.
  std::vector<RunRecord> records;
};

/// Runs the runs of `plan`'s shard that `store` has not finished, under `field`. Throws as said
/// above (InputError, or what the failing run threw). `field` is shared read-only by the workers.
BatchRunResult run_batch(const BatchPlan& plan, const AirFieldModel& field, const BatchStore& store,
                         const BatchRunOptions& options);

}  // namespace airtwin
