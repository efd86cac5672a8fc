// Batch throughput (issue 8's benchmark): runs per minute of `airtwin batch`'s runner on 1 and 2
// worker threads, on the same small batch in one benchmark run, and the scaling between them
// (target >= 1.8x on 2 cores). The batch: scenes/octagon.yaml (four tracers, the main job) x 6
// seeds in fast mode (truth perception), each run committed to a fresh batch folder as
// `airtwin batch` does. Wall clock, one iteration (a batch takes seconds).
//   BM_BatchScaling: counters runs_per_min_1, runs_per_min_2, scaling (= their ratio).
//   BM_BatchThroughput/J: runs per minute on J threads alone.

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "runs/batch_runner.h"

namespace airtwin {
namespace {

constexpr int kSeeds = 6;

// Wall-clock seconds of the whole batch on `jobs` threads, from an empty folder.
double batch_seconds(int jobs) {
  namespace fs = std::filesystem;
  static const BatchPlan plan =
      make_batch_plan({std::string(AIRTWIN_SOURCE_DIR) + "/scenes/octagon.yaml"}, 1, kSeeds, {});
  static const AirFieldModel field = AirFieldModel::with_constructed_table();
  const std::string dir =
      (fs::temp_directory_path() / ("airtwin_batch_bench_" + std::to_string(::getpid()))).string();
  fs::remove_all(dir);
  const BatchStore store(dir, BatchManifest::of_plan(plan, {{"perception", "truth"}}));
  BatchRunOptions options;
  options.jobs = jobs;
  const auto start = std::chrono::steady_clock::now();
  const BatchRunResult result = run_batch(plan, field, store, options);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  benchmark::DoNotOptimize(result.ran);
  fs::remove_all(dir);
  return s;
}

void BM_BatchThroughput(benchmark::State& state) {
  const int jobs = static_cast<int>(state.range(0));
  double total_s = 0.0;
  for (auto _ : state) {
    const double s = batch_seconds(jobs);
    state.SetIterationTime(s);
    total_s += s;
  }
  state.counters["runs_per_min"] = 60.0 * kSeeds * state.iterations() / total_s;
}

void BM_BatchScaling(benchmark::State& state) {
  double one_s = 0.0, two_s = 0.0;
  for (auto _ : state) {
    one_s = batch_seconds(1);
    two_s = batch_seconds(2);
    state.SetIterationTime(one_s + two_s);
  }
  state.counters["runs_per_min_1"] = 60.0 * kSeeds / one_s;
  state.counters["runs_per_min_2"] = 60.0 * kSeeds / two_s;
  state.counters["scaling"] = one_s / two_s;
}

BENCHMARK(BM_BatchScaling)->Iterations(1)->UseManualTime()->Unit(benchmark::kSecond);
BENCHMARK(BM_BatchThroughput)
    ->Arg(1)
    ->Arg(2)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kSecond);

}  // namespace
}  // namespace airtwin
