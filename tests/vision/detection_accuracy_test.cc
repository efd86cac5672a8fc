// The detection pipeline's acceptance figures, on frames rendered by the twin and scored against
// the twin's object positions:
//  - separated tracers and wads, clean frames: >= 99 % detected, mean error <= 3 mm, no false
//    positives, kinds right; with sensor noise 6 grey levels and blur 1 px: >= 95 %, <= 5 mm.
//    Through two cameras: the true one (camera_from_truth: detection alone) and the one
//    calibrated from rendered checkerboard frames (vision/camera_calibration.h), which is what
//    the pipeline uses on the rig;
//  - touching objects (packed tracers, tracers against wads, wads against wads): the rate is
//    measured and recorded, and only what holds with margin is asserted;
//  - tracking: objects blown across the floor by the jet keep their ids, also through frames in
//    which their detections are dropped, and their velocities match the twin's; two tracers
//    passing over each other (one blob for a few frames) keep theirs.
// Figures go to the test's XML properties and stdout (docs/vision.md quotes them).

#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

#include "renders/calibration_target.h"
#include "renders/camera_model.h"
#include "renders/frame_renderer.h"
#include "sim/twin.h"
#include "tests/support/scratch_dir.h"
#include "tests/vision/twin_frames.h"
#include "vision/camera_calibration.h"
#include "vision/object_detector.h"
#include "vision/tracker.h"

namespace airtwin {
namespace {

const AirFieldModel& field_model() {
  static const AirFieldModel model = AirFieldModel::with_constructed_table();
  return model;
}

ObjectKind kind_of(const std::string& type) {
  return type == "tracer" ? ObjectKind::kTracer : ObjectKind::kCotton;
}

std::vector<testing::TruthObject> twin_truth(const Twin& twin) {
  std::vector<testing::TruthObject> truth;
  for (size_t i = 0; i < twin.object_count(); ++i) {
    truth.push_back({twin.object_state(i).p_W, twin.object(i).type == ObjectType::kTracer
                                                   ? ObjectKind::kTracer
                                                   : ObjectKind::kCotton});
  }
  return truth;
}

// One line of figures; false positives only for a score over every object of the frame.
void report(const std::string& name, const testing::Score& s, bool whole_frame = true) {
  std::printf("%-20s objects %4d detected %5.1f %% mean %.2f mm max %.2f mm wrong kind %d",
              name.c_str(), s.objects, 100.0 * s.rate(), 1e3 * s.mean_error_m(),
              1e3 * s.max_error_m, s.wrong_kind);
  if (whole_frame) std::printf(" false positives %d", s.false_positives);
  std::printf("\n");
  ::testing::Test::RecordProperty(name + "_rate", std::to_string(s.rate()));
  ::testing::Test::RecordProperty(name + "_mean_mm", std::to_string(1e3 * s.mean_error_m()));
}

class DetectionAccuracy : public ::testing::Test {
 protected:
  // The camera as the pipeline knows it: calibrated once from 8 rendered views of the board.
  static void SetUpTestSuite() {
    const std::filesystem::path dir =
        std::filesystem::path(testing::scratch_root()) / "detection_accuracy";
    CalibrationDatasetOptions options;
    options.views = 8;
    options.seed = 3;
    write_calibration_dataset(dir.string(), SceneParameters{}, options);
    calibrated_ = new CalibratedCamera(calibrate_camera(dir.string()).camera);
    std::filesystem::remove_all(dir);
  }
  static void TearDownTestSuite() {
    delete calibrated_;
    calibrated_ = nullptr;
  }
  static CalibratedCamera* calibrated_;
};
CalibratedCamera* DetectionAccuracy::calibrated_ = nullptr;

TEST_F(DetectionAccuracy, SeparatedObjectsCleanAndNoisy) {
  // Three settled twins of 40 objects each (every third a wad), 15 cm apart at least.
  testing::Score clean_truth_camera, clean, noisy;
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    SceneSpec spec;
    spec.objects = testing::scattered_layout(40, 3, seed);
    spec.source = "accuracy scene";
    const Twin twin(spec, TwinParameters{}, field_model(), seed);
    const std::vector<testing::TruthObject> truth = twin_truth(twin);
    const GroundTruthCamera truth_camera = GroundTruthCamera::from_model(twin.model());
    ObjectDetector ideal(testing::camera_from_truth(truth_camera));
    ObjectDetector detector(*calibrated_);

    FrameRenderer renderer(twin.model());
    const cv::Mat frame = renderer.render(twin.data(), 0);
    clean_truth_camera.add(testing::score(ideal.detect(frame), truth));
    clean.add(testing::score(detector.detect(frame), truth));

    RenderOptions degraded;
    degraded.noise_sigma_grey = 6.0;
    degraded.blur_sigma_px = 1.0;
    degraded.seed = 100 + seed;
    FrameRenderer noisy_renderer(twin.model(), degraded);
    for (int k = 0; k < 3; ++k) {
      noisy.add(testing::score(detector.detect(noisy_renderer.render(twin.data(), k)), truth));
    }
  }
  report("clean_true_camera", clean_truth_camera);
  report("clean_calibrated", clean);
  report("noisy_calibrated", noisy);
  for (const testing::Score* s : {&clean_truth_camera, &clean}) {
    EXPECT_GE(s->rate(), 0.99);
    EXPECT_LE(s->mean_error_m(), 0.003);
    EXPECT_EQ(s->false_positives, 0);
    EXPECT_EQ(s->wrong_kind, 0);
  }
  EXPECT_GE(noisy.rate(), 0.95);
  EXPECT_LE(noisy.mean_error_m(), 0.005);
  EXPECT_EQ(noisy.wrong_kind, 0);
}

TEST_F(DetectionAccuracy, TouchingObjectsMeasured) {
  // Contact distances: tracers 3.02 cm (hemispheres touching), tracer-wad 3.6 cm and wad-wad
  // 4.4 cm (wads are soft and irregular: their visible discs of ~4.1 cm meet); a hexagonal
  // cluster of 19 tracers, pairs, a wad between two tracers, three wads in a clump.
  std::vector<ObjectSpec> objects;
  auto add = [&](const char* type, double x, double y) {
    std::string id = "o";
    id += std::to_string(objects.size());
    objects.push_back({id, type, {x, y}, std::nullopt});
  };
  const double tt = 0.0302, tc = 0.036, cc = 0.044;
  for (int a = -2; a <= 2; ++a) {
    for (int b = -2; b <= 2; ++b) {
      if (std::abs(a + b) <= 2) add("tracer", -0.3 + tt * (a + 0.5 * b), -0.7 + tt * 0.866 * b);
    }
  }
  const size_t cluster = objects.size();
  add("tracer", -0.8, 0.8);
  add("tracer", -0.8 + tt, 0.8);
  add("tracer", -0.4, 0.8);
  add("cotton", -0.4 + tc, 0.8);
  add("cotton", 0.2, 0.8);
  add("cotton", 0.2 + cc, 0.8);
  add("tracer", 0.6, 0.3);
  add("cotton", 0.6 + tc, 0.3);
  add("tracer", 0.6 + 2 * tc, 0.3);
  add("cotton", -0.7, -0.2);
  add("cotton", -0.7 + cc, -0.2);
  add("cotton", -0.7 + cc / 2, -0.2 + cc * 0.866);

  testing::Score all_clean, all_noisy, cluster_clean, cluster_noisy;
  for (uint64_t seed = 1; seed <= 2; ++seed) {
    const testing::PosedScene s = testing::make_posed_scene(objects, seed);
    std::vector<testing::TruthObject> truth, cluster_truth;
    for (size_t i = 0; i < objects.size(); ++i) {
      truth.push_back({s.truth(i), kind_of(objects[i].type)});
      if (i < cluster) cluster_truth.push_back(truth.back());
    }
    ObjectDetector detector(*calibrated_);
    FrameRenderer renderer(s.model());
    RenderOptions degraded;
    degraded.noise_sigma_grey = 6.0;
    degraded.blur_sigma_px = 1.0;
    degraded.seed = seed;
    FrameRenderer noisy_renderer(s.model(), degraded);
    const std::vector<Detection> clean = detector.detect(renderer.render(s.d(), 0));
    const std::vector<Detection> noisy = detector.detect(noisy_renderer.render(s.d(), 0));
    all_clean.add(testing::score(clean, truth, 0.01));
    all_noisy.add(testing::score(noisy, truth, 0.01));
    cluster_clean.add(testing::score(clean, cluster_truth, 0.01));
    cluster_noisy.add(testing::score(noisy, cluster_truth, 0.01));
  }
  report("touching_clean", all_clean);
  report("touching_noisy", all_noisy);
  report("packed19_clean", cluster_clean, false);
  report("packed19_noisy", cluster_noisy, false);
  // Asserted with margin below what is measured (docs/vision.md).
  EXPECT_GE(all_clean.rate(), 0.9);
  EXPECT_GE(all_noisy.rate(), 0.9);
  EXPECT_GE(cluster_clean.rate(), 0.95);
  EXPECT_GE(cluster_noisy.rate(), 0.95);
  EXPECT_LE(all_clean.mean_error_m(), 0.003);
  EXPECT_LE(all_noisy.mean_error_m(), 0.004);
  EXPECT_EQ(all_clean.wrong_kind, 0);
}

TEST_F(DetectionAccuracy, TrackingObjectsBlownByTheJet) {
  // Ten objects (a third wads) on the far side of the jet's stagnation point (tilt 20 deg), blown
  // outward, away from the rig, at up to ~1 m/s for 1.25 s at 40 Hz, in mildly noisy frames.
  // Object 0's detections are dropped in frames 20-24 (missed detections).
  const NozzleOrientation aim{0.3, 20.0 * M_PI / 180.0};
  TwinParameters params;
  params.jet_on_at_start = true;
  params.initial_orientation = aim;
  SceneSpec spec;
  spec.source = "tracking scene";
  {
    // The stagnation point of this orientation, from a twin without objects.
    const Twin probe(SceneSpec{}, params, field_model(), 1);
    const Eigen::Vector2d s = probe.field().stagnation_point();
    const double outward = std::atan2(s.y(), s.x());
    for (int k = 0; k < 10; ++k) {
      const double angle = outward + (k - 4.5) * 0.25, r = 0.12 + 0.03 * (k % 3);
      std::string id = "o";
      id += std::to_string(k);
      spec.objects.push_back({id, k % 3 == 2 ? "cotton" : "tracer",
                              s + r * Eigen::Vector2d(std::cos(angle), std::sin(angle)),
                              std::nullopt});
    }
  }
  Twin twin(spec, params, field_model(), 5);
  twin.settle_jet();
  RenderOptions degraded;
  degraded.noise_sigma_grey = 3.0;
  degraded.blur_sigma_px = 0.7;
  degraded.seed = 8;
  FrameRenderer renderer(twin.model(), degraded);
  ObjectDetector detector(*calibrated_);
  TrackerOptions options;
  options.image_width_px = calibrated_->width_px;
  options.image_height_px = calibrated_->height_px;
  Tracker tracker(options);

  const int frames = 50;
  std::vector<int> id_of(twin.object_count(), 0);
  int id_changes = 0, visible = 0, matched = 0, velocity_samples = 0;
  double velocity_error = 0.0, fastest = 0.0;
  cv::Mat image;
  for (int f = 0; f < frames; ++f) {
    renderer.render_into(twin.data(), f, image);
    std::vector<Detection> ds = detector.detect(image);
    const std::vector<testing::TruthObject> truth = twin_truth(twin);
    const bool dropping = f >= 20 && f < 25;
    if (dropping) {
      std::erase_if(ds, [&](const Detection& d) { return (d.p_W - truth[0].p_W).norm() < 0.015; });
    }
    tracker.update(f / 40.0, ds);
    // Each object in view: its detection (nearest within 1.5 cm) and the id it carries, which
    // must stay the first one it got; its velocity against the twin's once the fit has 5 frames.
    for (size_t i = 0; i < truth.size(); ++i) {
      const Eigen::Vector2d& p = truth[i].p_W;
      if (std::max(std::abs(p.x()), std::abs(p.y())) > 1.3 || p.norm() < 0.12) continue;
      if (!(dropping && i == 0)) ++visible;
      int best = -1;
      for (size_t j = 0; j < ds.size(); ++j) {
        if ((ds[j].p_W - p).norm() < 0.015 &&
            (best < 0 || (ds[j].p_W - p).norm() < (ds[best].p_W - p).norm())) {
          best = static_cast<int>(j);
        }
      }
      if (best < 0) continue;
      ++matched;
      const int id = tracker.detection_ids()[best];
      if (id_of[i] == 0) id_of[i] = id;
      id_changes += id != id_of[i];
      for (const Track& track : tracker.tracks()) {
        if (track.id != id || track.hits < 5) continue;
        velocity_error += (track.v_W - twin.object_state(i).v_W).norm();
        fastest = std::max(fastest, twin.object_state(i).v_W.norm());
        ++velocity_samples;
      }
    }
    twin.advance(1.0 / 40.0);
  }
  const TrackerCounters& c = tracker.counters();
  const double mean_velocity_error = velocity_error / std::max(1, velocity_samples);
  std::printf(
      "tracking: %d of %d object-frames in view detected, %d id changes, tracks %lld "
      "(new %lld, lost %lld, left %lld), missed %lld, merged %lld, mean velocity error "
      "%.3f m/s (fastest %.2f m/s)\n",
      matched, visible, id_changes, static_cast<long long>(tracker.tracks().size()),
      static_cast<long long>(c.new_tracks), static_cast<long long>(c.lost),
      static_cast<long long>(c.left_view), static_cast<long long>(c.missed),
      static_cast<long long>(c.merged), mean_velocity_error, fastest);
  RecordProperty("velocity_error_mps", std::to_string(mean_velocity_error));
  EXPECT_EQ(id_changes, 0);
  EXPECT_GE(matched, 0.98 * visible);
  EXPECT_EQ(c.new_tracks, static_cast<int64_t>(twin.object_count()));
  EXPECT_GE(c.missed, 5);
  EXPECT_GT(fastest, 0.3);  // they did move
  EXPECT_LT(mean_velocity_error, 0.05);
}

TEST_F(DetectionAccuracy, IdsSurviveTwoTracersPassingOverEachOther) {
  // Kinematic (bodies moved, not simulated): two tracers on parallel lines 8 mm apart, moving
  // toward each other at 0.2 m/s each; for a few frames their discs overlap into one blob (the
  // detector reports one object, or two in the wrong places), then they part. A third tracer
  // stands still nearby.
  std::vector<ObjectSpec> objects = {{"a", "tracer", {0.3, 0.5}, std::nullopt},
                                     {"b", "tracer", {0.5, 0.508}, std::nullopt},
                                     {"c", "tracer", {0.4, 0.6}, std::nullopt}};
  testing::PosedScene s = testing::make_posed_scene(objects, 1, 0.0);
  FrameRenderer renderer(s.model());
  ObjectDetector detector(*calibrated_);
  Tracker tracker;
  auto place = [&](size_t i, const Eigen::Vector2d& p) {
    const int body = s.scene.objects[i].root_body;
    const int q = s.model()->jnt_qposadr[s.model()->body_jntadr[body]];
    s.data->qpos[q] = p.x();
    s.data->qpos[q + 1] = p.y();
  };
  std::map<int, int> first_id;
  int id_changes = 0, frames_with_fewer = 0;
  for (int f = 0; f <= 40; ++f) {
    const double t = f / 40.0;
    place(0, {0.3 + 0.2 * t, 0.5});
    place(1, {0.5 - 0.2 * t, 0.508});
    mj_forward(s.model(), s.data.get());
    const std::vector<Detection> ds = detector.detect(renderer.render(s.d(), f));
    tracker.update(t, ds);
    frames_with_fewer += ds.size() < 3;
    // Ids are checked where the objects are apart (> 2.5 cm).
    if (std::abs(0.2 - 0.4 * t) < 0.025) continue;
    for (size_t i = 0; i < 3; ++i) {
      const Eigen::Vector2d p = s.truth(i);
      for (size_t j = 0; j < ds.size(); ++j) {
        if ((ds[j].p_W - p).norm() > 0.01) continue;
        const int id = tracker.detection_ids()[j];
        if (!first_id.count(static_cast<int>(i))) first_id[static_cast<int>(i)] = id;
        id_changes += id != first_id[static_cast<int>(i)];
      }
    }
  }
  std::printf("passing: %d frames with fewer than 3 detections, merged %lld, id changes %d\n",
              frames_with_fewer, static_cast<long long>(tracker.counters().merged), id_changes);
  EXPECT_GT(frames_with_fewer, 0);  // the blobs did merge
  EXPECT_EQ(id_changes, 0);
  EXPECT_EQ(tracker.counters().new_tracks, 3);
}

}  // namespace
}  // namespace airtwin
