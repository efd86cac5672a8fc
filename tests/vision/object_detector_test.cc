// Object detection: classification and splitting on drawn frames of known shapes (through a
// camera straight down, as the twin's), then on frames of the twin against its object positions:
// separated tracers and wads, a packed cluster of tracers, wads touching tracers, the rig.

#include "vision/object_detector.h"

#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "common/errors.h"
#include "renders/camera_model.h"
#include "renders/frame_renderer.h"
#include "tests/vision/painted_shapes.h"
#include "tests/vision/twin_frames.h"

namespace airtwin {
namespace {

// The twin's camera in numbers: 3.2 m above the origin, looking down, f = 1213.63 px, 1024 px
// square; world +x is image right, +y image up.
CalibratedCamera downward_camera() {
  CalibratedCamera c;
  c.width_px = c.height_px = 1024;
  c.K << 1213.63, 0, 511.5, 0, 1213.63, 511.5, 0, 0, 1;
  c.R_CW = Eigen::Vector3d(1, -1, -1).asDiagonal();
  c.t_C = -c.R_CW * Eigen::Vector3d(0, 0, 3.2);
  return c;
}

using test::draw_ellipse;

cv::Mat floor_frame() { return cv::Mat(1024, 1024, CV_8UC3, cv::Scalar(85, 85, 85)); }

// Radii of the visible discs at the twin's scale: tracer 2.8 cm -> 5.3 px, wad 4.1 cm -> 7.8 px.
constexpr double kTracerRadiusPx = 5.3, kCottonRadiusPx = 7.8;

const Detection* nearest(const std::vector<Detection>& ds, const Eigen::Vector2d& uv) {
  const Detection* best = nullptr;
  for (const Detection& d : ds) {
    if (!best || (d.centre_px - uv).norm() < (best->centre_px - uv).norm()) best = &d;
  }
  return best;
}

TEST(ObjectDetector, DrawnShapesAreClassifiedAndPlaced) {
  cv::Mat frame = floor_frame();
  const Eigen::Vector2d tracer(200.3, 300.7), wad(700.2, 250.4), oval(300.5, 800.1);
  draw_ellipse(frame, tracer, kTracerRadiusPx, kTracerRadiusPx);
  draw_ellipse(frame, wad, kCottonRadiusPx, kCottonRadiusPx);
  draw_ellipse(frame, oval, 9.0, 6.8, 0.7);  // an irregular wad
  cv::line(frame, cv::Point(800, 700), cv::Point(900, 760), cv::Scalar(255, 255, 255), 2);
  const CalibratedCamera camera = downward_camera();
  ObjectDetector detector(camera);
  const std::vector<Detection>& ds = detector.detect(frame);
  ASSERT_EQ(ds.size(), 3u);
  const std::vector<std::pair<Eigen::Vector2d, ObjectKind>> truth = {
      {tracer, ObjectKind::kTracer}, {wad, ObjectKind::kCotton}, {oval, ObjectKind::kCotton}};
  for (const auto& [uv, kind] : truth) {
    const Detection* d = nearest(ds, uv);
    EXPECT_EQ(d->kind, kind);
    EXPECT_LT((d->centre_px - uv).norm(), 0.15);
    EXPECT_EQ(d->objects_in_blob, 1);
    // World position: the pixel's ray at the kind's height.
    const double z = kind == ObjectKind::kTracer ? 0.005 : 0.016;
    const Eigen::Vector2d back = *camera.project({d->p_W.x(), d->p_W.y(), z});
    EXPECT_LT((back - d->centre_px).norm(), 1e-6);
  }
  EXPECT_EQ(detector.stats().empty_blobs, 1);  // the line
}

TEST(ObjectDetector, TouchingObjectsAreSplit) {
  // A row of three tracers, a triangle of three, a tracer against a wad, two wads, each pair
  // overlapping by ~1 px as blur makes touching objects do (objects that merely touch in a sharp
  // frame leave a dark pixel between them, or a neck that the opening cuts: separate blobs).
  cv::Mat frame = floor_frame();
  const double pitch = 9.6;
  std::vector<std::pair<Eigen::Vector2d, ObjectKind>> truth;
  for (int k = 0; k < 3; ++k) truth.push_back({{150.0 + pitch * k, 150.0}, ObjectKind::kTracer});
  truth.push_back({{400.0, 150.0}, ObjectKind::kTracer});
  truth.push_back({{400.0 + pitch, 150.0}, ObjectKind::kTracer});
  truth.push_back({{400.0 + pitch / 2, 150.0 + pitch * 0.866}, ObjectKind::kTracer});
  truth.push_back({{700.0, 200.0}, ObjectKind::kTracer});
  truth.push_back({{700.0 + 12.0, 200.0 + 2.0}, ObjectKind::kCotton});
  truth.push_back({{250.0, 700.0}, ObjectKind::kCotton});
  truth.push_back({{250.0 + 14.0, 700.0 + 3.0}, ObjectKind::kCotton});
  for (const auto& [uv, kind] : truth) {
    const double r = kind == ObjectKind::kTracer ? kTracerRadiusPx : kCottonRadiusPx;
    draw_ellipse(frame, uv, r, r);
  }
  ObjectDetector detector(downward_camera());
  const std::vector<Detection>& ds = detector.detect(frame);
  EXPECT_EQ(ds.size(), truth.size());
  EXPECT_EQ(detector.stats().merged_blobs, 4);
  for (const auto& [uv, kind] : truth) {
    const Detection* d = nearest(ds, uv);
    ASSERT_NE(d, nullptr);
    EXPECT_EQ(d->kind, kind) << uv.transpose();
    EXPECT_LT((d->centre_px - uv).norm(), 1.0) << uv.transpose();
    EXPECT_GT(d->objects_in_blob, 1);
  }
}

TEST(ObjectDetector, TheRigIsMaskedOut) {
  // Whatever bright reaches within 5 cm (19 px) of the floor's origin is the nozzle rig, or an
  // object whose image merges with the rig's: dropped. Beside it, objects are seen.
  cv::Mat frame = floor_frame();
  draw_ellipse(frame, {511.5, 511.5}, 12.5, 12.5);                        // the rod seen end-on
  draw_ellipse(frame, {511.5, 534.5}, kTracerRadiusPx, kTracerRadiusPx);  // reaching in
  draw_ellipse(frame, {548.0, 511.5}, kTracerRadiusPx, kTracerRadiusPx);  // 9.6 cm out
  ObjectDetector detector(downward_camera());
  ASSERT_FALSE(detector.rig_mask().empty());
  const std::vector<Detection>& ds = detector.detect(frame);
  ASSERT_EQ(ds.size(), 1u);
  EXPECT_NEAR(ds[0].centre_px.x(), 548.0, 0.15);
  EXPECT_EQ(detector.stats().masked_blobs, 1);  // the rod is wholly inside: no blob at all
  ObjectDetectorOptions no_mask;
  no_mask.rig_mask_radius_m = 0;
  EXPECT_GE(ObjectDetector(downward_camera(), no_mask).detect(frame).size(), 3u);
}

TEST(ObjectDetector, TwinFrameSeparatedObjects) {
  // Twelve objects, a third wads, apart; positions against the twin's to 2 mm.
  const std::vector<ObjectSpec> objects = testing::scattered_layout(12, 3, 21);
  const testing::PosedScene s = testing::make_posed_scene(objects, 4);
  FrameRenderer renderer(s.model());
  const GroundTruthCamera truth_camera = GroundTruthCamera::from_model(s.model());
  ObjectDetector detector(testing::camera_from_truth(truth_camera));
  const std::vector<Detection> ds = detector.detect(renderer.render(s.d(), 0));
  std::vector<testing::TruthObject> truth;
  for (size_t i = 0; i < objects.size(); ++i) {
    truth.push_back(
        {s.truth(i), objects[i].type == "tracer" ? ObjectKind::kTracer : ObjectKind::kCotton});
  }
  const testing::Score score = testing::score(ds, truth);
  EXPECT_EQ(score.detected, 12);
  EXPECT_EQ(score.false_positives, 0);
  EXPECT_EQ(score.wrong_kind, 0);
  EXPECT_LT(score.max_error_m, 0.002);
  EXPECT_EQ(detector.stats().masked_blobs, 0);
}

TEST(ObjectDetector, TwinFramePackedTracersAndTouchingWads) {
  // A hexagonal cluster of 7 touching tracers (3.02 cm apart), tracers against wads, two wads
  // touching: split into the right objects, each within 2.5 mm.
  std::vector<ObjectSpec> objects;
  auto add = [&](const char* type, double x, double y) {
    std::string id = "o";
    id += std::to_string(objects.size());
    objects.push_back({id, type, {x, y}, std::nullopt});
  };
  const double g = 0.0302;
  add("tracer", 0.6, -0.5);
  for (int q = 0; q < 6; ++q)
    add("tracer", 0.6 + g * std::cos(q * M_PI / 3), -0.5 + g * std::sin(q * M_PI / 3));
  add("cotton", -0.5, 0.5);
  add("tracer", -0.5 + 0.036, 0.5);
  add("cotton", 0.4, 0.6);
  add("cotton", 0.4 + 0.044, 0.6);
  const testing::PosedScene s = testing::make_posed_scene(objects, 2);
  FrameRenderer renderer(s.model());
  ObjectDetector detector(testing::camera_from_truth(GroundTruthCamera::from_model(s.model())));
  const std::vector<Detection> ds = detector.detect(renderer.render(s.d(), 0));
  std::vector<testing::TruthObject> truth;
  for (size_t i = 0; i < objects.size(); ++i) {
    truth.push_back(
        {s.truth(i), objects[i].type == "tracer" ? ObjectKind::kTracer : ObjectKind::kCotton});
  }
  const testing::Score score = testing::score(ds, truth, 0.01);
  EXPECT_EQ(score.detected, static_cast<int>(objects.size()));
  EXPECT_EQ(score.false_positives, 0);
  EXPECT_EQ(score.wrong_kind, 0);
  EXPECT_LT(score.max_error_m, 0.0025);
  int in_cluster = 0;
  for (const Detection& d : ds) in_cluster += d.objects_in_blob == 7;
  EXPECT_EQ(in_cluster, 7);
}

TEST(ObjectDetector, BadInputIsAnInputError) {
  ObjectDetector detector(downward_camera());
  EXPECT_THROW(detector.detect(cv::Mat(100, 100, CV_8UC3, cv::Scalar(0, 0, 0))), InputError);
  EXPECT_THROW(detector.detect(cv::Mat()), InputError);
  ObjectDetectorOptions o;
  o.tracer_visible_diameter_m = 0.06;  // bigger than a wad
  EXPECT_THROW(ObjectDetector(downward_camera(), o), InputError);
  EXPECT_THROW(ObjectDetector(CalibratedCamera{}), InputError);
  EXPECT_STREQ(object_kind_name(ObjectKind::kCotton), "cotton");
}

}  // namespace
}  // namespace airtwin
