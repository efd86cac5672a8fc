// Air-field evaluation speed (issue target: <= 20 ns per point, one thread, 1e6 points).
//
// BM_FieldSpeeds / BM_FieldVelocities: the product path (OrientedField batch evaluation).
// BM_FieldReferencePerPoint: the same numbers computed the straightforward way, for comparison in
// the same run: Makima in tilt rebuilt for the two neighbouring alpha rows at every point.
// BM_OrientedFieldBuild: cost of preparing one orientation (paid once per candidate in CEM).
// BM_CfdLookup: the twin's air from the CFD (models/cfd_field.h), one point at a time as the twin
// asks for it: mean velocity, k and epsilon at a point and height, at a tilt between two cases
// (issue target: <= 50 ns a lookup); 1e6 random points over +-1.25 m and 4-25 mm.

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "common/units.h"
#include "models/air_field.h"
#include "models/cfd_field.h"
#include "models/makima.h"

namespace airtwin {
namespace {

constexpr int kPoints = 1'000'000;

const AirFieldModel& model() {
  static const AirFieldModel m = AirFieldModel::with_constructed_table();
  return m;
}

Eigen::Matrix2Xd random_points() {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-1.25, 1.25);
  Eigen::Matrix2Xd p(2, kPoints);
  for (int j = 0; j < kPoints; ++j) p.col(j) << u(rng), u(rng);
  return p;
}

void BM_FieldSpeeds(benchmark::State& state) {
  const Eigen::Matrix2Xd p = random_points();
  const OrientedField f = model().at({deg_to_rad(90), deg_to_rad(17)});
  Eigen::VectorXd out(kPoints);
  for (auto _ : state) {
    f.speeds(p, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * kPoints);
  state.counters["ns_per_point"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * kPoints * 1e-9,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_FieldSpeeds)->Unit(benchmark::kMillisecond);

void BM_FieldVelocities(benchmark::State& state) {
  const Eigen::Matrix2Xd p = random_points();
  const OrientedField f = model().at({deg_to_rad(90), deg_to_rad(17)});
  Eigen::Matrix2Xd out(2, kPoints);
  for (auto _ : state) {
    f.velocities(p, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * kPoints);
  state.counters["ns_per_point"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * kPoints * 1e-9,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_FieldVelocities)->Unit(benchmark::kMillisecond);

void BM_FieldReferencePerPoint(benchmark::State& state) {
  const Eigen::Matrix2Xd p = random_points();
  const NozzleOrientation o{deg_to_rad(90), deg_to_rad(17)};
  const Eigen::Vector2d s = stagnation_point(model().geometry(), o);
  const FieldTable& t = model().table();
  Eigen::VectorXd out(kPoints);
  for (auto _ : state) {
    for (int j = 0; j < kPoints; ++j) {
      const Eigen::Vector2d d = p.col(j) - s;
      double a = rad_to_deg(std::atan2(d.y(), d.x()) - o.pan_rad);
      a -= 360.0 * std::floor(a / 360.0);
      const int k = static_cast<int>(a) % 360;
      const double w = a - std::floor(a);
      double b[2][3];
      for (int side = 0; side < 2; ++side) {
        const int row = (k + side) % 360;
        std::vector<double> y1, y2, y3;
        for (size_t i = 0; i < t.n_tilts(); ++i) {
          y1.push_back(t.at(i, row).b1);
          y2.push_back(t.at(i, row).b2);
          y3.push_back(t.at(i, row).b3);
        }
        b[side][0] = Makima(t.tilts_rad(), y1)(o.tilt_rad);
        b[side][1] = Makima(t.tilts_rad(), y2)(o.tilt_rad);
        b[side][2] = Makima(t.tilts_rad(), y3)(o.tilt_rad);
      }
      const FieldCoefficients c{(1 - w) * b[0][0] + w * b[1][0], (1 - w) * b[0][1] + w * b[1][1],
                                (1 - w) * b[0][2] + w * b[1][2]};
      out[j] = c.speed(d.norm());
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * kPoints);
  state.counters["ns_per_point"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * kPoints * 1e-9,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_FieldReferencePerPoint)->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_OrientedFieldBuild(benchmark::State& state) {
  double tilt = 0.0;
  for (auto _ : state) {
    OrientedField f = model().at({0.3, tilt});
    benchmark::DoNotOptimize(&f);
    tilt = tilt > 0.7 ? 0.0 : tilt + 0.01;
  }
}
BENCHMARK(BM_OrientedFieldBuild)->Unit(benchmark::kMicrosecond);

void BM_CfdLookup(benchmark::State& state) {
  static const CfdField cfd = CfdField::read_dir(AIRTWIN_SOURCE_DIR "/data/cfd");
  const Eigen::Matrix2Xd p = random_points();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> height(0.004, 0.025);
  Eigen::VectorXd z(kPoints);
  for (int j = 0; j < kPoints; ++j) z[j] = height(rng);
  const CfdOrientedField f = cfd.at({deg_to_rad(90), deg_to_rad(17)});
  for (auto _ : state) {
    double sum = 0.0;
    for (int j = 0; j < kPoints; ++j) {
      const CfdSample a = f.at(p.col(j), z[j]);
      sum += a.u_W.x() + a.k;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * kPoints);
  state.counters["ns_per_point"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * kPoints * 1e-9,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_CfdLookup)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace airtwin
