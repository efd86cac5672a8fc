// Detection and tracking time per frame (issue target: <= 10 ms, so that the pipeline keeps up
// with the 40 Hz camera with room for the controller). The frames: 25 objects (17 tracers and 8
// cotton wads on a jittered 5 x 5 grid of 0.26 m pitch, the aggregation scene's layout) blown by
// the jet for 1 s, 40 frames rendered by the twin at 1024 x 1024 and kept in memory (untimed), the
// camera model built from the renderer's true pinhole (what calibration gives, to < 0.1 %).
//   BM_DetectTrack/clean:       ObjectDetector::detect + Tracker::update per frame, default look.
//   BM_DetectTrack/noise_blur:  the same with sensor noise 6 grey levels and blur 1 px.
//   BM_DetectOnly/clean:        the detector alone.
//   BM_TrackOnly:               the tracker alone, on the frames' detections.
// One thread (OpenCV's own parallel loops as configured: the grey conversion and the opening may
// use both cores). Counter objects = detections per frame.

#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "renders/camera_model.h"
#include "renders/frame_renderer.h"
#include "sim/twin.h"
#include "vision/calibrated_camera.h"
#include "vision/object_detector.h"
#include "vision/tracker.h"

namespace airtwin {
namespace {

constexpr int kFrames = 40;
constexpr double kCameraPeriod_s = 1.0 / 40.0;

struct Sequence {
  CalibratedCamera camera;
  std::vector<cv::Mat> frames;
};

// The twin's 25-object scene, blown by the jet at tilt 20 deg; kFrames frames with `options`.
Sequence render_sequence(const RenderOptions& options) {
  SceneSpec spec;
  for (int i = 0; i < 25; ++i) {
    const double jx = 0.05 * std::sin(1.7 * i + 0.3), jy = 0.05 * std::cos(2.3 * i + 1.1);
    std::string id = "o";
    id += std::to_string(i);
    spec.objects.push_back({id,
                            i % 3 == 1 ? "cotton" : "tracer",
                            {0.26 * (i % 5 - 2) + jx, 0.26 * (i / 5 - 2) + jy},
                            0.0});
  }
  static const AirFieldModel field = AirFieldModel::with_constructed_table();
  TwinParameters params;
  params.jet_on_at_start = true;
  params.initial_orientation = {0.5, 20.0 * 3.14159265358979 / 180.0};
  Twin twin(spec, params, field, 7);
  twin.settle_jet();
  FrameRenderer renderer(twin.model(), options);
  Sequence s;
  // The camera: the true pinhole, in OpenCV's camera frame (x right, y down, z forward).
  const GroundTruthCamera truth = GroundTruthCamera::from_model(twin.model());
  s.camera.width_px = truth.width_px();
  s.camera.height_px = truth.height_px();
  s.camera.K = truth.intrinsics();
  s.camera.R_CW = Eigen::Vector3d(1, -1, -1).asDiagonal() * truth.R_WC().transpose();
  s.camera.t_C = -s.camera.R_CW * truth.p_WC();
  for (int f = 0; f < kFrames; ++f) {
    s.frames.push_back(renderer.render(twin.data(), f));
    twin.advance(kCameraPeriod_s);
  }
  return s;
}

const Sequence& clean_sequence() {
  static const Sequence s = render_sequence(RenderOptions{});
  return s;
}

const Sequence& noisy_sequence() {
  static const Sequence s = [] {
    RenderOptions o;
    o.noise_sigma_grey = 6.0;
    o.blur_sigma_px = 1.0;
    o.seed = 3;
    return render_sequence(o);
  }();
  return s;
}

void detect_and_track(benchmark::State& state, const Sequence& s) {
  ObjectDetector detector(s.camera);
  Tracker tracker;
  int64_t frame = 0, detections = 0;
  for (auto _ : state) {
    const std::vector<Detection>& ds = detector.detect(s.frames[frame % kFrames]);
    // Time keeps increasing: the sequence replays as if the objects jumped back (new tracks).
    const std::vector<Track>& tracks = tracker.update(frame * kCameraPeriod_s, ds);
    benchmark::DoNotOptimize(tracks.data());
    detections += static_cast<int64_t>(ds.size());
    ++frame;
  }
  state.counters["objects"] = static_cast<double>(detections) / static_cast<double>(frame);
}

void BM_DetectTrack_clean(benchmark::State& state) { detect_and_track(state, clean_sequence()); }
void BM_DetectTrack_noise_blur(benchmark::State& state) {
  detect_and_track(state, noisy_sequence());
}

void BM_DetectOnly_clean(benchmark::State& state) {
  const Sequence& s = clean_sequence();
  ObjectDetector detector(s.camera);
  int64_t frame = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(detector.detect(s.frames[frame++ % kFrames]).data());
  }
}

void BM_TrackOnly(benchmark::State& state) {
  const Sequence& s = clean_sequence();
  std::vector<std::vector<Detection>> detections;
  ObjectDetector detector(s.camera);
  for (const cv::Mat& frame : s.frames) detections.push_back(detector.detect(frame));
  Tracker tracker;
  int64_t frame = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        tracker.update(frame * kCameraPeriod_s, detections[frame % kFrames]).data());
    ++frame;
  }
}

BENCHMARK(BM_DetectTrack_clean)
    ->Name("BM_DetectTrack/clean")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0)
    ->UseRealTime();
BENCHMARK(BM_DetectTrack_noise_blur)
    ->Name("BM_DetectTrack/noise_blur")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0)
    ->UseRealTime();
BENCHMARK(BM_DetectOnly_clean)
    ->Name("BM_DetectOnly/clean")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();
BENCHMARK(BM_TrackOnly)->Unit(benchmark::kMicrosecond)->MinTime(1.0);

}  // namespace
}  // namespace airtwin
