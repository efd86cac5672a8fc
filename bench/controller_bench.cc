// CEM decision time (issue 6's benchmark): one decision of the controller on the situations of the
// paper's two multi-object tasks, on one core.
//   BM_CemDecision/aggregation: 25 tracers of scenes/aggregation.yaml, all referenced to the zone
//     centre; the line search of section V-C (n 25, n* 3, i_max 5) with the scenario's mu0 and
//     Sigma0.
//   BM_CemDecision/sorting: the 3 tracers + 3 cotton wads of scenes/sorting.yaml, each referenced
//     to its type's zone, in stages (tracers first, cottons deferred); the plane search (n 100,
//     n* 10, i_max 5) after the file's 10 cm scan of the reachable stagnation points;
//     sorting_no_scan: the same search started from the objects' mean, as the paper does;
//     the file predicts the re-aim (predict_transition: the nozzle turning from a previous
//     command at pan 140 deg, the jet sweeping): sorting_no_transition predicts the new s at once.
// Each iteration is one full decision (every iteration of CEM, all predictions with the fast
// predictor over Delta T = 1.5 s). Counters: evaluations (candidates predicted), iterations.
// Target: <= 5 ms each.
//   BM_CemDecision/octagon, and */extended (octagon, sorting, aggregation): the same decision
//     planned with an extended model
//     (a nozzle offset of (8, 4) deg and a 0.3 s response delay: the extended predictor at 2 ms
//     steps, the nozzle turning from a previous command), against the fast path in the same run.
//   BM_CemDecision/sorting_extended_2_threads: sorting_extended with its candidates predicted on
//     two threads (CemPlanner::set_threads; the same decision), timed on the wall clock.
// The files' sweep clearance (controller/cem_planner.h) is checked wherever a previous command is
// given (the sorting's and the */extended decisions); sorting_no_clearance and
// aggregation_extended_no_clearance are those decisions without it, in the same run.

#include <benchmark/benchmark.h>

#include <optional>
#include <string>
#include <vector>

#include "common/units.h"
#include "controller/cem_planner.h"
#include "controller/task.h"
#include "scenes/scenario.h"

namespace airtwin {
namespace {

void BM_CemDecision(benchmark::State& state, const std::string& name, bool extended,
                    bool no_scan = false, bool no_transition = false, bool no_clearance = false,
                    int threads = 1) {
  Scenario sc = read_scenario(std::string(AIRTWIN_SOURCE_DIR) + "/scenes/" + name + ".yaml");
  if (no_scan) sc.controller.scan_step_m = 0.0;
  if (no_clearance) sc.controller.sweep_clearance_m = 0.0;
  if (no_transition) sc.controller.predict_transition = false;
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  std::optional<ExtendedPlanning> planning;
  if (extended) {
    planning.emplace();
    planning->extensions.pan_offset_rad = 8.0 * kPi / 180.0;
    planning->extensions.tilt_offset_rad = 4.0 * kPi / 180.0;
    planning->extensions.extra_delay_s = 0.3;
  }
  CemPlanner planner(model, sc.controller, {}, planning);
  planner.set_threads(threads);
  std::vector<Eigen::Vector2d> p, v;
  std::vector<std::string> types;
  std::vector<ObjectDynamics> xi;
  for (const auto& o : sc.scene.objects) {
    p.push_back(o.p_W);
    v.push_back(Eigen::Vector2d::Zero());
    types.push_back(o.type);
    xi.push_back(o.type == "tracer" ? kTracerDynamics : kCottonDynamics);
  }
  TaskProgress progress(
      resolve_sorting_stages(sc.task, {{"tracer", kTracerDynamics.threshold_air_speed()},
                                       {"cotton", kCottonDynamics.threshold_air_speed()}}));
  // As the loop's first observation does: the octagon's group starts on its first corner, so the
  // reference moves on to the next one.
  progress.update(p, types, 0.0);
  const std::vector<Eigen::Vector2d> r = progress.references(types);
  const CostShaping shaping = progress.cost_shaping(p, types);
  PlanningProblem problem;
  problem.positions_W = p;
  problem.velocities_W = v;
  problem.dynamics = xi;
  problem.references_W = r;
  problem.weights = shaping.weights;
  problem.reach_m = shaping.reach_m;
  if (extended) problem.nozzle_now = NozzleOrientation{0.5, 0.3};
  // A previous command for the transition: s 0.66 m out at pan 140 deg, as sorting often has.
  if (sc.controller.predict_transition) {
    problem.nozzle_now = NozzleOrientation{140.0 * kPi / 180.0, 0.45};
  }
  RandomStream rng(1, RandomPurpose::kController, 0);
  int evaluations = 0, iterations = 0;
  for (auto _ : state) {
    const PlanResult result = planner.plan(problem, rng);
    benchmark::DoNotOptimize(result.cost);
    evaluations += result.evaluations;
    iterations += result.iterations;
  }
  state.counters["evaluations"] =
      benchmark::Counter(evaluations, benchmark::Counter::kAvgIterations);
  state.counters["iterations"] = benchmark::Counter(iterations, benchmark::Counter::kAvgIterations);
  state.counters["objects"] = static_cast<double>(p.size());
}

BENCHMARK_CAPTURE(BM_CemDecision, aggregation, std::string("aggregation"), false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CemDecision, sorting, std::string("sorting"), false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CemDecision, sorting_no_scan, std::string("sorting"), false, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CemDecision, sorting_no_transition, std::string("sorting"), false, false, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CemDecision, sorting_no_clearance, std::string("sorting"), false, false, false,
                  true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CemDecision, octagon, std::string("octagon"), false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CemDecision, octagon_extended, std::string("octagon"), true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CemDecision, sorting_extended, std::string("sorting"), true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CemDecision, sorting_extended_2_threads, std::string("sorting"), true, false,
                  false, false, 2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_CemDecision, aggregation_extended, std::string("aggregation"), true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CemDecision, aggregation_extended_no_clearance, std::string("aggregation"),
                  true, false, false, true)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace airtwin
