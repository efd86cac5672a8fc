// Our hand-written helpers against maintained Debian libraries that do the same job, on our use
// (docs/decisions.md, 2026-11-26 "hand-written or a library"):
//  - common/parallel_for.h against oneTBB's tbb::parallel_for (libtbb-dev, already installed as a
//    dependency of libopencv-core-dev) and OpenMP (GCC's libgomp), two threads, on 10 000 small
//    items (the pool's overhead shows) and 64 items of milliseconds (our items: a twin trial, a
//    cross-validation fold, a bootstrap fit are ms to s);
//  - common/csv.h's strict reader against libcsv (libcsv-dev), on a 100 000-row trajectory CSV
//    (`airtwin run`'s log.csv: 8 columns, 5 of them numbers), every number converted.
// Each variant computes the same per-item results; the benchmarks report time only.

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "common/csv.h"
#include "common/parallel_for.h"

#ifdef AIRTWIN_BENCH_TBB
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>
#endif
#ifdef AIRTWIN_BENCH_LIBCSV
#include <csv.h>
#endif

namespace airtwin {
namespace {

constexpr int kThreads = 2;

// About `iterations` x 5 ns of arithmetic the compiler cannot drop.
double work(size_t item, int iterations) {
  double x = 1.0 + 1e-9 * static_cast<double>(item);
  for (int i = 0; i < iterations; ++i) x = std::sqrt(x + 1.0);
  return x;
}

// Items: range(0) of them, range(1) iterations each (200: a few us; 200 000: a few ms). The
// serial loop is the reference: the work without any pool.
void BM_ParallelFor_Serial(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  const int iterations = static_cast<int>(state.range(1));
  std::vector<double> out(n);
  for (auto _ : state) {
    for (size_t k = 0; k < n; ++k) out[k] = work(k, iterations);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
}
BENCHMARK(BM_ParallelFor_Serial)->Args({10000, 200})->Args({64, 200000})->UseRealTime();

void BM_ParallelFor_Ours(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  const int iterations = static_cast<int>(state.range(1));
  std::vector<double> out(n);
  for (auto _ : state) {
    parallel_for(n, kThreads, [&](size_t k) { out[k] = work(k, iterations); });
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
}
BENCHMARK(BM_ParallelFor_Ours)->Args({10000, 200})->Args({64, 200000})->UseRealTime();

#ifdef AIRTWIN_BENCH_TBB
void BM_ParallelFor_Tbb(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  const int iterations = static_cast<int>(state.range(1));
  std::vector<double> out(n);
  tbb::task_arena arena(kThreads);
  for (auto _ : state) {
    arena.execute(
        [&] { tbb::parallel_for(size_t{0}, n, [&](size_t k) { out[k] = work(k, iterations); }); });
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
}
BENCHMARK(BM_ParallelFor_Tbb)->Args({10000, 200})->Args({64, 200000})->UseRealTime();
#endif

#ifdef AIRTWIN_BENCH_OPENMP
void BM_ParallelFor_OpenMp(benchmark::State& state) {
  const long n = static_cast<long>(state.range(0));
  const int iterations = static_cast<int>(state.range(1));
  std::vector<double> out(static_cast<size_t>(n));
  for (auto _ : state) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(kThreads)
    for (long k = 0; k < n; ++k) out[k] = work(static_cast<size_t>(k), iterations);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * n);
}
BENCHMARK(BM_ParallelFor_OpenMp)->Args({10000, 200})->Args({64, 200000})->UseRealTime();
#endif

// A trajectory CSV as `airtwin run` writes log.csv: 100 000 rows.
const std::string& trajectory_csv() {
  static const std::string text = [] {
    std::string t = "traj,object,t,x,y,pan_deg,tilt_deg,group\n";
    char row[160];
    for (int i = 0; i < 100000; ++i) {
      std::snprintf(row, sizeof(row), "t%d,tracer,%.6f,%.6f,%.6f,%.6f,%.6f,line\n", i / 4000,
                    0.025 * (i % 4000), std::sin(1e-3 * i), std::cos(1e-3 * i), 0.01 * (i % 360),
                    0.001 * (i % 450));
      t += row;
    }
    return t;
  }();
  return text;
}
const std::vector<std::string> kNumbers = {"t", "x", "y", "pan_deg", "tilt_deg"};

void BM_Csv_Ours(benchmark::State& state) {
  const std::string& text = trajectory_csv();
  for (auto _ : state) {
    const CsvTable table = CsvTable::parse(
        text, "log.csv", {"traj", "object", "t", "x", "y", "pan_deg", "tilt_deg"}, {"group"});
    double sum = 0.0;
    for (size_t r = 0; r < table.rows(); ++r) {
      for (const std::string& c : kNumbers) sum += table.number(r, c);
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_Csv_Ours)->Unit(benchmark::kMillisecond);

#ifdef AIRTWIN_BENCH_LIBCSV
// libcsv tokenises (quotes, embedded commas and line ends); the header, the column count, the
// numbers and every message are the caller's. Here: fields kept per row as strings, as CsvTable
// keeps them, and the five number columns converted with the same parse_finite_double.
struct LibcsvRows {
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> current;
};

void BM_Csv_Libcsv(benchmark::State& state) {
  const std::string& text = trajectory_csv();
  for (auto _ : state) {
    csv_parser parser;
    csv_init(&parser, CSV_STRICT | CSV_STRICT_FINI);
    LibcsvRows rows;
    auto on_field = [](void* field, size_t size, void* data) {
      static_cast<LibcsvRows*>(data)->current.emplace_back(static_cast<const char*>(field), size);
    };
    auto on_row = [](int, void* data) {
      auto* r = static_cast<LibcsvRows*>(data);
      r->rows.push_back(std::move(r->current));
      r->current.clear();
    };
    csv_parse(&parser, text.data(), text.size(), on_field, on_row, &rows);
    csv_fini(&parser, on_field, on_row, &rows);
    csv_free(&parser);
    double sum = 0.0;
    for (size_t r = 1; r < rows.rows.size(); ++r) {
      for (size_t c = 2; c <= 6; ++c) sum += parse_finite_double(rows.rows[r][c]).value_or(0.0);
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_Csv_Libcsv)->Unit(benchmark::kMillisecond);
#endif

}  // namespace
}  // namespace airtwin
