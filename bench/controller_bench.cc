// CEM decision time (issue 6's benchmark): one decision of the controller on the situations of the
// paper's two multi-object tasks, on one core.
//   BM_CemDecision/aggregation: 25 tracers of scenes/aggregation.yaml, all referenced to the zone
//     centre; the line search of section V-C (n 25, n* 3, i_max 5) with the scenario's mu0 and
//     Sigma0.
//   BM_CemDecision/sorting: the 3 tracers + 3 cotton wads of scenes/sorting.yaml, each referenced
//     to its type's zone; the plane search (n 100, n* 10, i_max 5).
// Each iteration is one full decision (every iteration of CEM, all predictions with the fast
// predictor over Delta T = 1.5 s). Counters: evaluations (candidates predicted), iterations.
// Target: <= 5 ms each.

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "controller/cem_planner.h"
#include "controller/task.h"
#include "scenes/scenario.h"

namespace airtwin {
namespace {

void BM_CemDecision(benchmark::State& state, const std::string& name) {
  const Scenario sc = read_scenario(std::string(AIRTWIN_SOURCE_DIR) + "/scenes/" + name + ".yaml");
  const AirFieldModel model = AirFieldModel::with_default_table();
  const CemPlanner planner(model, sc.controller);
  std::vector<Eigen::Vector2d> p, v;
  std::vector<std::string> types;
  std::vector<ObjectDynamics> xi;
  for (const auto& o : sc.scene.objects) {
    p.push_back(o.p_W);
    v.push_back(Eigen::Vector2d::Zero());
    types.push_back(o.type);
    xi.push_back(o.type == "tracer" ? kTracerDynamics : kCottonDynamics);
  }
  const TaskProgress progress(sc.task);
  const std::vector<Eigen::Vector2d> r = progress.references(types);
  PlanningProblem problem;
  problem.positions_W = p;
  problem.velocities_W = v;
  problem.dynamics = xi;
  problem.references_W = r;
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

BENCHMARK_CAPTURE(BM_CemDecision, aggregation, std::string("aggregation"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CemDecision, sorting, std::string("sorting"))->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace airtwin
