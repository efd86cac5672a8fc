#include "rigs/vision_perception.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "common/errors.h"
#include "renders/calibration_target.h"
#include "renders/frame_renderer.h"
#include "vision/camera_calibration.h"
#include "vision/object_detector.h"

namespace airtwin {

struct VisionPerception::Impl {
  VisionPerceptionOptions options;
  ObjectDetector detector;
  Tracker tracker;
  std::unique_ptr<FrameRenderer> renderer;
  cv::Mat frame;
  int stride = 4;
  int64_t processed = 0;
  double total_ms = 0.0;
  double last_t_s = -1.0;
  int64_t duplicates = 0;
  std::string detections_csv = kDetectionsCsvHeader;  // every processed frame's detections

  static TrackerOptions tracker_options(const CalibratedCamera& camera,
                                        const VisionPerceptionOptions& o) {
    TrackerOptions t;
    t.max_jump_m = o.max_speed_mps / o.rate_hz;
    t.image_width_px = camera.width_px;
    t.image_height_px = camera.height_px;
    // Coast ~1 s through merges and misses.
    t.max_missed_frames = std::max(2, static_cast<int>(std::lround(o.rate_hz)));
    return t;
  }

  Impl(const CalibratedCamera& camera, const VisionPerceptionOptions& o)
      : options(o), detector(camera), tracker(tracker_options(camera, o)) {
    const double k = 40.0 / o.rate_hz;
    if (!(std::isfinite(o.min_separation_m) && o.min_separation_m >= 0.0)) {
      throw InputError("vision: the minimum separation of objects must be a number >= 0 (m)");
    }
    if (!(std::isfinite(o.rate_hz) && o.rate_hz > 0.0 && std::fabs(k - std::round(k)) < 1e-9)) {
      throw InputError(
          "vision: the detection rate must divide the camera's 40 Hz (40, 20, 10, 8, 5, ...)");
    }
    stride = static_cast<int>(std::lround(k));
  }
};

VisionPerception::VisionPerception(const CalibratedCamera& camera,
                                   const VisionPerceptionOptions& options)
    : impl_(std::make_unique<Impl>(camera, options)) {}

VisionPerception::~VisionPerception() = default;

void VisionPerception::on_frame(const Twin& twin, int64_t frame_index) {
  Impl& m = *impl_;
  if (frame_index % m.stride != 0) return;
  const auto start = std::chrono::steady_clock::now();
  if (!m.renderer) {
    RenderOptions ro;
    ro.noise_sigma_grey = m.options.noise_sigma_grey;
    ro.blur_sigma_px = m.options.blur_sigma_px;
    ro.seed = m.options.seed;
    m.renderer = std::make_unique<FrameRenderer>(twin.model(), ro);
  }
  m.renderer->render_into(twin.data(), frame_index, m.frame);
  const std::vector<Detection>& detections = m.detector.detect(m.frame);
  m.tracker.update(twin.time(), detections);
  m.detections_csv += detection_rows_csv(m.tracker, detections, m.processed, twin.time());
  m.last_t_s = twin.time();
  ++m.processed;
  m.total_ms +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

Observation VisionPerception::observe(const Twin& twin) {
  Impl& m = *impl_;
  Observation o;
  o.t_s = twin.time();
  const TrackReport report = report_tracks(m.tracker.tracks(), m.last_t_s, m.options);
  o.objects = report.objects;
  m.duplicates += report.duplicates;
  const TrackerCounters& c = m.tracker.counters();
  o.out_of_view = static_cast<int>(std::max<int64_t>(0, c.left_view - c.entered_view));
  return o;
}

TrackReport report_tracks(const std::vector<Track>& tracks, double t_s,
                          const VisionPerceptionOptions& options) {
  TrackReport out;
  // Oldest first (ids count up), so that of two tracks on one object the older is kept.
  std::vector<const Track*> order;
  for (const Track& t : tracks) order.push_back(&t);
  std::sort(order.begin(), order.end(),
            [](const Track* a, const Track* b) { return a->id < b->id; });
  for (const Track* t : order) {
    if (t_s - t->t_last_s > options.report_missing_s) continue;
    const Eigen::Vector2d p = t->predict(t_s);
    bool duplicate = false;
    for (const ObservedObject& kept : out.objects) {
      duplicate = duplicate || (kept.p_W - p).norm() < options.min_separation_m;
    }
    if (duplicate) {
      ++out.duplicates;
      continue;
    }
    ObservedObject obj;
    obj.id = "v";
    obj.id += std::to_string(t->id);
    obj.type = object_kind_name(t->kind);
    obj.p_W = p;
    obj.v_W = t->v_W;
    out.objects.push_back(std::move(obj));
  }
  return out;
}

const TrackerCounters& VisionPerception::counters() const { return impl_->tracker.counters(); }
const std::string& VisionPerception::detections_csv() const { return impl_->detections_csv; }
int64_t VisionPerception::duplicates() const { return impl_->duplicates; }
int64_t VisionPerception::frames_processed() const { return impl_->processed; }
double VisionPerception::mean_frame_ms() const {
  return impl_->processed > 0 ? impl_->total_ms / static_cast<double>(impl_->processed) : 0.0;
}

CalibratedCamera calibrate_twin_camera(const std::string& dir, const SceneParameters& params,
                                       uint64_t seed, double noise_sigma_grey,
                                       double blur_sigma_px) {
  CalibrationDatasetOptions o;
  o.seed = seed;
  o.noise_sigma_grey = noise_sigma_grey;
  o.blur_sigma_px = blur_sigma_px;
  write_calibration_dataset(dir, params, o);
  return calibrate_camera(dir).camera;
}

}  // namespace airtwin
