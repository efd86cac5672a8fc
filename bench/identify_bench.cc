// Identification speed (issue figure): 100 tracer trajectories of 80 frames (2 s at 40 Hz,
// Appendix D), released at rest 20-58 cm from s at tilts 0 / 22.5 deg, with 1 mm detection noise.
// The trajectories are made once by the fast predictor (timing only; accuracy is tested in
// tests/models).
//
// BM_IdentifyTrajectories: the whole of `airtwin identify` after reading the file: glitch check,
//                          central differences, smoothing, robust E-SINDy with 15 bootstraps,
//                          conversion to continuous time, end-position replay.
// BM_SindyOnly:            robust E-SINDy (15 bootstraps) on the prepared speed pairs.
// BM_SpeedPairsOnly:       the preprocessing alone.
// The first two run each solver (SindyOptions::solver): kFast, the default, and kReference, the
// literal robustfit iteration it is checked against. Their counters dxi_ref / dxid_ref are the
// largest absolute difference of the continuous / discrete coefficients from the reference
// solver's on the same data (computed once, outside the timing; 0 for the reference itself).

#include <benchmark/benchmark.h>

#include <random>

#include "common/units.h"
#include "models/fast_predictor.h"
#include "models/identification.h"

namespace airtwin {
namespace {

const AirFieldModel& field() {
  static const AirFieldModel model = AirFieldModel::with_constructed_table();
  return model;
}

const TrajectorySet& data() {
  static const TrajectorySet set = [] {
    TrajectorySet s;
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> pan(-kPi, kPi), angle(-kPi, kPi), radius(0.2, 0.58);
    std::normal_distribution<double> noise(0.0, 0.001);
    const FastPredictor predictor;
    PredictionOptions po;
    po.horizon_s = 79 * 0.025;
    po.sample_rate_hz = 40.0;
    for (int i = 0; i < 100; ++i) {
      const NozzleOrientation o{pan(rng), deg_to_rad(i % 2 ? 22.5 : 0.0)};
      const OrientedField f = field().at(o);
      const double a = angle(rng);
      const ObjectState start{
          f.stagnation_point() + radius(rng) * Eigen::Vector2d(std::cos(a), std::sin(a)), 0.0};
      const Prediction p =
          predictor.predict(f, std::span(&kTracerDynamics, 1), std::span(&start, 1), po);
      Trajectory tr;
      tr.id = std::to_string(i);
      tr.object = "tracer";
      for (size_t k = 0; k < p.sample_times_s.size(); ++k) {
        const Eigen::Vector2d jitter(noise(rng), noise(rng));
        tr.samples.push_back({p.sample_times_s[k], p.sample(k, 0).p_W + jitter, o});
      }
      s.trajectories.push_back(tr);
    }
    return s;
  }();
  return set;
}

SindySolver solver_arg(const benchmark::State& state) {
  return state.range(1) ? SindySolver::kReference : SindySolver::kFast;
}

// Args: {threads, solver}: bootstraps fitted in parallel (1: one thread; 0: every core), solver
// (0: kFast, 1: kReference).
void threads_and_solvers(benchmark::internal::Benchmark* b) {
  b->Args({1, 0})->Args({0, 0})->Args({1, 1})->Args({0, 1});
  b->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
}

void BM_IdentifyTrajectories(benchmark::State& state) {
  const TrajectorySet& set = data();
  IdentificationOptions o;  // robust-esindy, 15 bootstraps
  o.sindy.threads = static_cast<int>(state.range(0));
  o.sindy.solver = solver_arg(state);
  IdentificationOptions ref = o;
  ref.sindy.solver = SindySolver::kReference;
  const IdentifiedModel a = identify_trajectories(set, "tracer", field(), o),
                        b = identify_trajectories(set, "tracer", field(), ref);
  for (auto _ : state) {
    const IdentifiedModel m = identify_trajectories(set, "tracer", field(), o);
    benchmark::DoNotOptimize(m.coefficients);
  }
  state.counters["xi1"] = a.coefficients[1];
  state.counters["xi2"] = a.coefficients[2];
  state.counters["xi3"] = a.coefficients[0];
  state.counters["dxi_ref"] = (a.coefficients - b.coefficients).cwiseAbs().maxCoeff();
  state.counters["dxid_ref"] = (a.discrete - b.discrete).cwiseAbs().maxCoeff();
  state.counters["noise_mm"] = 1e3 * a.position_noise_m;
  state.counters["end_mape_pct"] = a.end_position_mape_pct.value_or(-1);
  state.counters["pairs"] = static_cast<double>(a.n_pairs);
}
BENCHMARK(BM_IdentifyTrajectories)->Apply(threads_and_solvers);

void BM_SindyOnly(benchmark::State& state) {
  const SpeedPairs d = speed_pairs_from_trajectories(data(), field(), SpeedPairOptions{}, nullptr);
  SindyOptions o;
  o.threads = static_cast<int>(state.range(0));
  o.solver = solver_arg(state);
  SindyOptions ref = o;
  ref.solver = SindySolver::kReference;
  const SindyResult a = identify_sindy(d, o), b = identify_sindy(d, ref);
  for (auto _ : state) benchmark::DoNotOptimize(identify_sindy(d, o).continuous);
  state.counters["dxi_ref"] = (a.continuous - b.continuous).cwiseAbs().maxCoeff();
  state.counters["dxid_ref"] = (a.discrete - b.discrete).cwiseAbs().maxCoeff();
}
BENCHMARK(BM_SindyOnly)->Apply(threads_and_solvers);

void BM_SpeedPairsOnly(benchmark::State& state) {
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        speed_pairs_from_trajectories(data(), field(), SpeedPairOptions{}, nullptr).v);
  }
}
BENCHMARK(BM_SpeedPairsOnly)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace airtwin
