#include "runs/run_video.h"

#include <optional>

#include "common/errors.h"
#include "renders/camera_model.h"
#include "renders/frame_renderer.h"
#include "renders/overlay.h"

namespace airtwin {

struct RunVideo::Impl {
  TaskSpec task;
  std::string caption;
  int stride = 1;
  VideoWriter writer;
  std::unique_ptr<FrameRenderer> renderer;
  std::optional<GroundTruthCamera> camera;
  TrailHistory trails{800};
  std::vector<Eigen::Vector2d> references;
  cv::Mat frame;

  Impl(const std::string& path, const TaskSpec& t, std::string c, int s)
      : task(t), caption(std::move(c)), stride(s), writer(path, options_for(s)) {
    if (task.kind == TaskKind::kPath) references = path_references(task);
  }

  // The stride is applied here (frames not kept are not rendered at all), so the writer keeps
  // every frame it is given; its summary still reports the run's time scale.
  static VideoOptions options_for(int s) {
    if (s < 1) throw FieldError("video.stride", "must be >= 1");
    VideoOptions o;
    o.camera_rate_hz = 40.0 / s;
    return o;
  }
};

RunVideo::RunVideo(const std::string& path, const TaskSpec& task, const std::string& caption,
                   int stride)
    : impl_(std::make_unique<Impl>(path, task, caption, stride)) {}

RunVideo::~RunVideo() = default;

void RunVideo::on_frame(const Twin& twin, int64_t frame_index,
                        const std::vector<DecisionRecord>& decisions) {
  Impl& m = *impl_;
  // Trails follow every frame so that they stay smooth with a stride.
  std::vector<Eigen::Vector2d> p;
  for (const auto& s : twin.object_states()) p.push_back(s.p_W);
  m.trails.push(p);
  if (frame_index % m.stride != 0) return;
  if (!m.renderer) {
    m.renderer = std::make_unique<FrameRenderer>(twin.model());
    m.camera = GroundTruthCamera::from_model(twin.model());
  }
  m.renderer->render_into(twin.data(), frame_index, m.frame);

  OverlayData o;
  switch (m.task.kind) {
    case TaskKind::kPath:
      o.path_W = m.task.path_W;
      o.path_references_W = m.references;
      break;
    case TaskKind::kAggregation:
      o.zones.push_back(OverlayZone{m.task.zone.centre_W, m.task.zone.radius_m, ""});
      break;
    case TaskKind::kSorting:
      for (const auto& [type, zone] : m.task.zones_by_type) {
        o.zones.push_back(OverlayZone{zone.centre_W, zone.radius_m, type});
      }
      break;
  }
  if (!decisions.empty()) {
    o.current_references_W.push_back(decisions.back().reference_W);
    o.stagnation_W = twin.stagnation_point();
  }
  o.nozzle_pan_rad = twin.actual_orientation().pan_rad;
  o.trails_W = m.trails.trails();
  o.time_s = twin.time();
  o.caption = m.caption + ", decision " + std::to_string(decisions.size());
  draw_overlay(m.frame, *m.camera, o);
  m.writer.write(m.frame);
}

VideoSummary RunVideo::close() { return impl_->writer.close(); }

}  // namespace airtwin
