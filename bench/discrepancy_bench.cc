// The discrepancy analysis (issue 7): one whole `analyse_discrepancy` on Appendix D data from the
// twin, as `airtwin discrepancy` runs it (baseline, the catalogue's candidates fitted and tested,
// forward selection; the window evaluations spread over the machine's cores).
//   BM_DiscrepancyAnalysis/trials:N/screen:S: N tracer trials (half at 0 deg, half at 22.5 deg),
//     0.5 s lead-in, a nozzle offset of (6, 4) deg hidden in them. The data are collected once,
//     outside the timing. S = 1: the fits' grids ranked at the 8 ms screening step (the default);
//     S = 0: every prediction at the 1 ms step (the reference: the fits as they ran before the
//     screening). Counters: windows, candidates fitted, found (1 when the offset was found),
//     predictions of the training windows at the full and at the screening step.

#include <benchmark/benchmark.h>

#include <map>
#include <string>

#include "models/air_field.h"
#include "models/discrepancy.h"
#include "models/object_dynamics.h"
#include "sim/collection.h"
#include "sim/effects.h"

namespace airtwin {
namespace {

TrajectorySet collected(int trials) {
  CollectionOptions options;
  options.per_tilt = trials / 2;
  options.seed = 3;
  options.lead_in_s = 0.5;
  options.threads = 0;
  apply_effects({parse_effect("nozzle_offset:pan_deg=6,tilt_deg=4")}, &options.twin);
  return run_collection(options, AirFieldModel::with_constructed_table());
}

void BM_DiscrepancyAnalysis(benchmark::State& state) {
  const TrajectorySet data = collected(static_cast<int>(state.range(0)));
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  const std::map<std::string, ObjectDynamics> objects = {{"tracer", kTracerDynamics}};
  DiscrepancyOptions options;
  if (state.range(1) == 0) options.screen_step_s = options.predictor_step_s;
  DiscrepancyReport report;
  for (auto _ : state) {
    report = analyse_discrepancy(data, field, objects, options);
    benchmark::DoNotOptimize(report.gain_pct);
  }
  size_t fitted = 0;
  double full = 0.0, screened = 0.0;
  for (const auto& round : report.rounds) {
    fitted += round.size();
    for (const CandidateResult& c : round) {
      full += c.fit_evaluations;
      screened += c.fit_screen_evaluations;
    }
  }
  state.counters["full_step_predictions"] = full;
  state.counters["screen_step_predictions"] = screened;
  state.counters["windows"] = static_cast<double>(report.n_windows);
  state.counters["candidates_fitted"] = static_cast<double>(fitted);
  state.counters["found"] =
      report.found.size() == 1 && report.found[0] == "nozzle_offset" ? 1.0 : 0.0;
}

BENCHMARK(BM_DiscrepancyAnalysis)
    ->ArgNames({"trials", "screen"})
    ->Args({40, 1})
    ->Args({100, 1})
    ->Args({100, 0})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace
}  // namespace airtwin
