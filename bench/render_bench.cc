// Render frame rate (issue 5's benchmark): the top camera's 1024 x 1024 frames of the 25-tracer
// aggregation scene, rendered by MuJoCo into an OSMesa (llvmpipe) context and read back as a BGR
// image, with the twin's look (renders/frame_renderer.h). Target: >= 40 frames/s, the camera's
// rate, on the 2-core machine.
//
// Each iteration renders one frame; between frames (untimed) the twin advances one camera period
// (25 ms) with the jet on and the nozzle re-aimed every second, so the frames are a real sequence.
//   BM_RenderFrame/clean:       the default look (no multisampling, no blur, no noise).
//   BM_RenderFrame/noise_blur:  plus blur sigma 1 px and sensor noise sigma 3 grey levels.
//   BM_RenderFrame/msaa4:       MuJoCo's default 4x offscreen multisampling, for comparison.
//   BM_EncodePng:               one such frame encoded as PNG (what writing a dataset adds).
// Counter fps = frames per wall-clock second of the timed part (real time: llvmpipe rasterises in
// its own threads, so the calling thread's CPU time undercounts). llvmpipe's rasteriser threads
// follow LP_NUM_THREADS (default: the number of cores).

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include "common/units.h"
#include "renders/frame_renderer.h"
#include "renders/png.h"
#include "sim/twin.h"

namespace airtwin {
namespace {

constexpr double kCameraPeriod_s = 1.0 / 40.0;

const AirFieldModel& render_field_model() {
  static const AirFieldModel model = AirFieldModel::with_constructed_table();
  return model;
}

// The aggregation scene of bench/twin_bench.cc: 25 tracers on a 5 x 5 grid of 0.26 m pitch with
// a fixed +-5 cm jitter.
SceneSpec aggregation_25() {
  SceneSpec spec;
  for (int i = 0; i < 25; ++i) {
    const double jx = 0.05 * std::sin(1.7 * i + 0.3), jy = 0.05 * std::cos(2.3 * i + 1.1);
    std::string id = "t";
    id += std::to_string(i);
    spec.objects.push_back({id, "tracer", {0.26 * (i % 5 - 2) + jx, 0.26 * (i / 5 - 2) + jy}, 0.0});
  }
  return spec;
}

// Tilt 20 deg, pan stepping by 90 deg every second.
NozzleOrientation aim(double t_s) {
  const int k = static_cast<int>(std::floor(t_s)) % 4;
  return {-kPi / 2 + k * kPi / 2, deg_to_rad(20)};
}

Twin make_render_twin() {
  TwinParameters p;
  p.jet_on_at_start = true;
  p.initial_orientation = aim(0.0);
  Twin twin(aggregation_25(), p, render_field_model(), 7);
  twin.settle_jet();
  return twin;
}

void advance_one_frame(Twin& twin) {
  const NozzleOrientation target = aim(twin.time());
  if (target.pan_rad != twin.commanded_orientation().pan_rad) twin.command_nozzle(target);
  twin.advance(kCameraPeriod_s);
}

void run(benchmark::State& state, const RenderOptions& options) {
  Twin twin = make_render_twin();
  FrameRenderer renderer(twin.model(), options);
  cv::Mat image;
  int64_t frame = 0;
  for (auto _ : state) {
    renderer.render_into(twin.data(), frame++, image);
    benchmark::DoNotOptimize(image.data);
    state.PauseTiming();
    advance_one_frame(twin);
    state.ResumeTiming();
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(frame), benchmark::Counter::kIsRate);
  const char* lp = std::getenv("LP_NUM_THREADS");
  state.SetLabel(renderer.gl_renderer() + ", LP_NUM_THREADS=" + (lp ? lp : "default"));
}

void BM_RenderFrame_clean(benchmark::State& state) { run(state, RenderOptions{}); }

void BM_RenderFrame_noise_blur(benchmark::State& state) {
  RenderOptions options;
  options.noise_sigma_grey = 3.0;
  options.blur_sigma_px = 1.0;
  options.seed = 1;
  run(state, options);
}

void BM_RenderFrame_msaa4(benchmark::State& state) {
  RenderOptions options;
  options.multisamples = 4;
  run(state, options);
}

void BM_EncodePng(benchmark::State& state) {
  Twin twin = make_render_twin();
  twin.advance(1.0);
  FrameRenderer renderer(twin.model());
  const cv::Mat image = renderer.render(twin.data(), 0);
  size_t bytes = 0;
  for (auto _ : state) {
    bytes = encode_png(image).size();
    benchmark::DoNotOptimize(bytes);
  }
  state.counters["kB"] = static_cast<double>(bytes) / 1000.0;
}

BENCHMARK(BM_RenderFrame_clean)
    ->Name("BM_RenderFrame/clean")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0)
    ->UseRealTime();
BENCHMARK(BM_RenderFrame_noise_blur)
    ->Name("BM_RenderFrame/noise_blur")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0)
    ->UseRealTime();
BENCHMARK(BM_RenderFrame_msaa4)
    ->Name("BM_RenderFrame/msaa4")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0)
    ->UseRealTime();
BENCHMARK(BM_EncodePng)->Unit(benchmark::kMillisecond)->MinTime(1.0);

}  // namespace
}  // namespace airtwin
