#include "runs/camera_collection.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>
#include <thread>

#include "common/errors.h"
#include "common/parallel_for.h"
#include "renders/frame_renderer.h"
#include "vision/object_detector.h"
#include "vision/tracker.h"

namespace airtwin {
namespace {

// A track is missed at the image's edge when its predicted pixel is this close to it (px): the
// tracker's own margin for tracks leaving the view.
constexpr double kBorderMarginPx = 12.0;

}  // namespace

void CameraCollectionOptions::validate() const {
  collection.validate();
  if (!(std::isfinite(noise_sigma_grey) && noise_sigma_grey >= 0.0 && noise_sigma_grey <= 64.0)) {
    throw FieldError("camera_collection.noise_sigma_grey", "expected grey levels in [0, 64]");
  }
  if (!(std::isfinite(blur_sigma_px) && blur_sigma_px >= 0.0 && blur_sigma_px <= 10.0)) {
    throw FieldError("camera_collection.blur_sigma_px", "expected pixels in [0, 10]");
  }
  if (!(std::isfinite(max_speed_mps) && max_speed_mps > 0.0 && max_speed_mps <= 50.0)) {
    throw FieldError("camera_collection.max_speed_mps", "expected a speed in (0, 50] m/s");
  }
  if (!(std::isfinite(start_radius_m) && start_radius_m > 0.0 && start_radius_m <= 1.0)) {
    throw FieldError("camera_collection.start_radius_m", "expected a distance in (0, 1] m");
  }
}

const char* camera_trial_outcome_name(CameraTrialOutcome outcome) {
  switch (outcome) {
    case CameraTrialOutcome::kKept:
      return "kept";
    case CameraTrialOutcome::kNotFoundAtStart:
      return "not found at the start";
    case CameraTrialOutcome::kLost:
      return "lost";
    case CameraTrialOutcome::kLeftView:
      return "left the view";
  }
  return "?";
}

CameraTrialResult run_camera_collection_trial(const CollectionTrial& trial,
                                              const CameraCollectionOptions& o,
                                              const AirFieldModel& field,
                                              const CalibratedCamera& camera) {
  o.validate();
  const CollectionOptions& c = o.collection;
  CameraTrialResult result;
  for (Trajectory* tr : {&result.camera, &result.truth}) {
    tr->id = std::to_string(trial.index);
    tr->object = c.object;
  }

  // The camera and the vision pipeline of this trial alone (its noise seeded by the trial).
  RenderOptions render_options;
  render_options.noise_sigma_grey = o.noise_sigma_grey;
  render_options.blur_sigma_px = o.blur_sigma_px;
  render_options.seed = trial.twin_seed;
  std::unique_ptr<FrameRenderer> renderer;  // made on the first frame: it needs the twin's model
  ObjectDetector detector(camera);
  TrackerOptions tracker_options;
  tracker_options.max_jump_m = o.max_speed_mps / c.frame_rate_hz;
  tracker_options.border_margin_px = kBorderMarginPx;
  tracker_options.image_width_px = camera.width_px;
  tracker_options.image_height_px = camera.height_px;
  Tracker tracker(tracker_options);
  cv::Mat frame_bgr;
  int object_id = -1;  // the trial's object's track
  bool dropped = false;

  run_collection_trial(
      trial, c, field,
      [&](const Twin& twin, int frame, double t_s, const NozzleOrientation& command) {
        if (dropped) return;  // the rest of a dropped trial is not recorded
        if (!renderer) renderer = std::make_unique<FrameRenderer>(twin.model(), render_options);
        renderer->render_into(twin.data(), frame, frame_bgr);
        const std::vector<Detection>& detections = detector.detect(frame_bgr);
        tracker.update(t_s, detections);
        const std::vector<int>& ids = tracker.detection_ids();

        // The first frame: the object is the detection nearest where it was placed.
        if (object_id < 0) {
          double best_m = o.start_radius_m;
          for (size_t i = 0; i < detections.size(); ++i) {
            const double d = (detections[i].p_W - trial.start_W).norm();
            if (d <= best_m) {
              best_m = d;
              object_id = ids[i];
            }
          }
          if (object_id < 0) {
            result.outcome = CameraTrialOutcome::kNotFoundAtStart;
            dropped = true;
            return;
          }
        }

        // Its detection in this frame, or the reason it has none.
        const Detection* seen = nullptr;
        for (size_t i = 0; i < detections.size(); ++i) {
          if (ids[i] == object_id) seen = &detections[i];
        }
        if (seen == nullptr) {
          const Track* track = nullptr;
          for (const std::vector<Track>* list : {&tracker.tracks(), &tracker.ended()}) {
            for (const Track& t : *list) {
              if (t.id == object_id) track = &t;
            }
          }
          AIRTWIN_DEMAND(track != nullptr);
          const Eigen::Vector2d uv = track->centre_px + track->v_px * (t_s - track->t_last_s);
          const bool at_edge = uv.x() < kBorderMarginPx || uv.y() < kBorderMarginPx ||
                               uv.x() > camera.width_px - 1 - kBorderMarginPx ||
                               uv.y() > camera.height_px - 1 - kBorderMarginPx;
          result.outcome = at_edge ? CameraTrialOutcome::kLeftView : CameraTrialOutcome::kLost;
          dropped = true;
          return;
        }
        result.camera.samples.push_back({t_s, seen->p_W, command});
        result.truth.samples.push_back({t_s, twin.object_state(0).p_W, command});
      });
  return result;
}

CameraCollectionResult run_camera_collection(const std::vector<CollectionTrial>& plan,
                                             const CameraCollectionOptions& o,
                                             const AirFieldModel& field,
                                             const CalibratedCamera& camera,
                                             const std::function<void(int, int)>& progress) {
  o.validate();
  const int n = static_cast<int>(plan.size());
  std::vector<CameraTrialResult> trials(plan.size());
  const int threads = o.collection.threads == 0
                          ? static_cast<int>(std::thread::hardware_concurrency())
                          : o.collection.threads;
  std::mutex mutex;  // guards done and the progress callback
  int done = 0;
  parallel_for(plan.size(), threads, [&](size_t i) {
    CameraTrialResult r = run_camera_collection_trial(plan[i], o, field, camera);
    const std::lock_guard lock(mutex);
    trials[i] = std::move(r);
    ++done;
    if (progress) progress(done, n);
  });

  // The tally, in plan order: kept trials and the camera's error against the truth.
  CameraCollectionResult out;
  out.planned = n;
  double sum_sq = 0.0;
  for (CameraTrialResult& r : trials) {
    switch (r.outcome) {
      case CameraTrialOutcome::kKept:
        ++out.kept;
        for (size_t k = 0; k < r.camera.samples.size(); ++k) {
          const double e = (r.camera.samples[k].p_W - r.truth.samples[k].p_W).norm();
          sum_sq += e * e;
          out.max_error_m = std::max(out.max_error_m, e);
          ++out.positions;
        }
        out.camera.trajectories.push_back(std::move(r.camera));
        out.truth.trajectories.push_back(std::move(r.truth));
        break;
      case CameraTrialOutcome::kNotFoundAtStart:
        ++out.not_found_at_start;
        break;
      case CameraTrialOutcome::kLost:
        ++out.lost;
        break;
      case CameraTrialOutcome::kLeftView:
        ++out.left_view;
        break;
    }
  }
  if (out.positions > 0) out.rms_error_m = std::sqrt(sum_sq / static_cast<double>(out.positions));
  return out;
}

CameraCollectionResult run_camera_collection(const CameraCollectionOptions& o,
                                             const AirFieldModel& field,
                                             const CalibratedCamera& camera,
                                             const std::function<void(int, int)>& progress) {
  return run_camera_collection(plan_collection(o.collection), o, field, camera, progress);
}

}  // namespace airtwin
