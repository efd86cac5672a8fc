// Trajectory prediction speed: the controller's work (section V-A), 25 objects over the 1.5 s
// horizon under each of 125 candidate orientations (tilt 0-45 deg, any pan; objects 20-58 cm from
// each candidate's s, at rest or moving), default table.
//
// BM_FastPredictor:          the fast path (FastPredictor, default step).
// BM_FastPredictorSampled:   the same with 40 Hz samples (camera frames).
// BM_CvodeEqualAccuracy:     CVODE at the loosest tolerances that keep the end positions within
//                            1 mm of the reference (rtol 1e-3, atol 1e-4; measured, see below).
// BM_CvodeReference:         CVODE at the reference tolerances (rtol 1e-10, atol 1e-12).
// BM_FastVsCvode:            both on the same work in one run: us per object for each, their
//                            ratio, and each one's max end-position error against the reference.
// Counter us_per_object: time per object per 1.5 s horizon.

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <random>
#include <vector>

#include "common/units.h"
#include "models/cvode_predictor.h"
#include "models/fast_predictor.h"

namespace airtwin {
namespace {

constexpr int kCandidates = 125;
constexpr int kObjects = 25;

struct Candidate {
  OrientedField field;
  std::vector<ObjectState> start;
};

struct Work {
  std::vector<Candidate> candidates;
  std::vector<ObjectDynamics> dynamics;
  std::vector<Prediction> reference;  // CVODE at the reference tolerances
};

const Work& work() {
  static const Work w = [] {
    Work w;
    const AirFieldModel model = AirFieldModel::with_constructed_table();
    std::mt19937_64 rng(2024);
    std::uniform_real_distribution<double> pan(-kPi, kPi), tilt(0.0, deg_to_rad(45)),
        angle(-kPi, kPi), radius(0.20, 0.58), u01(0.0, 1.0);
    for (int j = 0; j < kObjects; ++j) {
      w.dynamics.push_back(j % 5 == 4 ? kCottonDynamics : kTracerDynamics);
    }
    for (int c = 0; c < kCandidates; ++c) {
      Candidate cand{model.at({pan(rng), tilt(rng)}), {}};
      for (int j = 0; j < kObjects; ++j) {
        const double a = angle(rng), r = radius(rng);
        const double v = u01(rng) < 0.5 ? 0.0 : 0.8 * u01(rng);
        cand.start.push_back(
            {cand.field.stagnation_point() + r * Eigen::Vector2d(std::cos(a), std::sin(a)), v});
      }
      w.candidates.push_back(std::move(cand));
    }
    const CvodePredictor reference;
    for (const Candidate& c : w.candidates) {
      w.reference.push_back(reference.predict(c.field, w.dynamics, c.start));
    }
    return w;
  }();
  return w;
}

CvodePredictor::Options equal_accuracy_cvode() {
  CvodePredictor::Options o;
  o.rtol = 1e-3;
  o.atol = 1e-4;
  return o;
}

// Runs `p` over all candidates; returns the max end-position error (m) against the reference.
double run_all(const TrajectoryPredictor& p, const PredictionOptions& options, Prediction& out) {
  const Work& w = work();
  double max_error = 0.0;
  for (size_t c = 0; c < w.candidates.size(); ++c) {
    p.predict(w.candidates[c].field, w.dynamics, w.candidates[c].start, options, out);
    for (int j = 0; j < kObjects; ++j) {
      max_error = std::max(max_error, (out.end[j].p_W - w.reference[c].end[j].p_W).norm());
    }
  }
  return max_error;
}

void report_per_object(benchmark::State& state, double max_error) {
  state.SetItemsProcessed(state.iterations() * kCandidates * kObjects);
  state.counters["us_per_object"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * kCandidates * kObjects * 1e-6,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["max_err_mm"] = max_error * 1e3;
}

// Times `p` over all candidates and reports per-object time and the end error.
void time_predictor(benchmark::State& state, const TrajectoryPredictor& p,
                    const PredictionOptions& options = {}) {
  work();
  Prediction out;
  double max_error = 0.0;
  for (auto _ : state) {
    max_error = run_all(p, options, out);
    benchmark::DoNotOptimize(out.end.data());
    benchmark::DoNotOptimize(out.samples.data());
  }
  report_per_object(state, max_error);
}

void BM_FastPredictor(benchmark::State& state) { time_predictor(state, FastPredictor()); }
BENCHMARK(BM_FastPredictor)->Unit(benchmark::kMillisecond);

void BM_FastPredictorSampled(benchmark::State& state) {
  PredictionOptions options;
  options.sample_rate_hz = 40.0;
  time_predictor(state, FastPredictor(), options);
}
BENCHMARK(BM_FastPredictorSampled)->Unit(benchmark::kMillisecond);

void BM_CvodeEqualAccuracy(benchmark::State& state) {
  time_predictor(state, CvodePredictor(equal_accuracy_cvode()));
}
BENCHMARK(BM_CvodeEqualAccuracy)->Unit(benchmark::kMillisecond);

void BM_CvodeReference(benchmark::State& state) { time_predictor(state, CvodePredictor()); }
BENCHMARK(BM_CvodeReference)->Unit(benchmark::kMillisecond)->Iterations(3);

// Both paths on the same work, timed inside one benchmark so the ratio comes from one run.
void BM_FastVsCvode(benchmark::State& state) {
  work();
  const FastPredictor fast;
  const CvodePredictor cvode(equal_accuracy_cvode());
  Prediction out;
  double fast_s = 0.0, cvode_s = 0.0, fast_error = 0.0, cvode_error = 0.0;
  constexpr int kFastRepeats = 20;  // the fast path is too quick to time once against CVODE
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int rep = 0; rep < kFastRepeats; ++rep) fast_error = run_all(fast, {}, out);
    const auto t1 = std::chrono::steady_clock::now();
    cvode_error = run_all(cvode, {}, out);
    const auto t2 = std::chrono::steady_clock::now();
    fast_s += std::chrono::duration<double>(t1 - t0).count() / kFastRepeats;
    cvode_s += std::chrono::duration<double>(t2 - t1).count();
    benchmark::DoNotOptimize(out.end.data());
  }
  const double objects = static_cast<double>(state.iterations()) * kCandidates * kObjects;
  state.counters["fast_us_per_object"] = fast_s / objects * 1e6;
  state.counters["cvode_us_per_object"] = cvode_s / objects * 1e6;
  state.counters["speedup"] = cvode_s / fast_s;
  state.counters["fast_max_err_mm"] = fast_error * 1e3;
  state.counters["cvode_max_err_mm"] = cvode_error * 1e3;
}
BENCHMARK(BM_FastVsCvode)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace airtwin
