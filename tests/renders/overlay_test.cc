// Overlays land where the floor points are: expected pixels are computed here from the scene's
// geometry alone (2 * camera_half_view_m of floor across 1024 px, the origin at the image centre,
// world +y up), not from the camera model the overlay uses.

#include "renders/overlay.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/errors.h"
#include "sim/scene_builder.h"

namespace airtwin {
namespace {

class OverlayTest : public ::testing::Test {
 protected:
  OverlayTest()
      : scene_(build_scene(SceneSpec{}, SceneParameters{}, 1)),
        camera_(GroundTruthCamera::from_model(scene_.model.get())) {}

  // Pixel (u, v) of floor point (x, y) from the scene's numbers only.
  static Eigen::Vector2d expected_px(double x, double y) {
    const SceneParameters p;
    const double px_per_m = p.camera_resolution_px / (2.0 * p.camera_half_view_m);
    const double centre = (p.camera_resolution_px - 1) / 2.0;
    return {centre + x * px_per_m, centre - y * px_per_m};
  }
  static double px_per_m() {
    const SceneParameters p;
    return p.camera_resolution_px / (2.0 * p.camera_half_view_m);
  }
  static cv::Vec3b at(const cv::Mat& image, const Eigen::Vector2d& uv) {
    return image.at<cv::Vec3b>(static_cast<int>(std::lround(uv.y())),
                               static_cast<int>(std::lround(uv.x())));
  }
  static double colour_distance(const cv::Vec3b& a, const cv::Scalar& b) {
    return std::sqrt(std::pow(a[0] - b[0], 2) + std::pow(a[1] - b[1], 2) +
                     std::pow(a[2] - b[2], 2));
  }
  cv::Mat black() const { return cv::Mat(1024, 1024, CV_8UC3, cv::Scalar::all(0)); }

  BuiltScene scene_;
  GroundTruthCamera camera_;
  OverlayStyle style_;
};

TEST_F(OverlayTest, ZoneColoursItsRimAndTintsItsInsideOnly) {
  OverlayData data;
  data.zones.push_back({{0.5, -0.3}, 0.1, ""});
  cv::Mat image = black();
  draw_overlay(image, camera_, data);

  const Eigen::Vector2d c = expected_px(0.5, -0.3);
  const double r = 0.1 * px_per_m();  // ~37.9 px
  // The rim, in four directions: the zone's colour.
  for (const Eigen::Vector2d& dir : {Eigen::Vector2d(1, 0), Eigen::Vector2d(-1, 0),
                                     Eigen::Vector2d(0, 1), Eigen::Vector2d(0, -1)}) {
    EXPECT_LT(colour_distance(at(image, c + r * dir), style_.zone_bgr), 60.0) << dir.transpose();
  }
  // Inside: black moved 18 % toward the zone colour.
  const cv::Vec3b inside = at(image, c + Eigen::Vector2d(0.3 * r, 0.2 * r));
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(inside[k], style_.zone_fill_alpha * style_.zone_bgr[k], 1.0) << k;
  }
  // Nothing drawn away from the zone (the 2 px rim and its anti-aliasing reach ~r + 2.5 px).
  int stray = 0;
  for (int v = 0; v < image.rows; ++v) {
    for (int u = 0; u < image.cols; ++u) {
      if (image.at<cv::Vec3b>(v, u) == cv::Vec3b(0, 0, 0)) continue;
      if ((Eigen::Vector2d(u, v) - c).norm() > r + 4.0) ++stray;
    }
  }
  EXPECT_EQ(stray, 0);
}

TEST_F(OverlayTest, MarkersPathTrailsAndHeadingLandOnTheirFloorPoints) {
  OverlayData data;
  data.path_W = {{-0.6, 0.6}, {0.0, 0.6}};
  data.trails_W = {{{-0.6, -0.6}, {-0.2, -0.6}}};
  data.stagnation_W = Eigen::Vector2d(0.8, 0.4);
  data.current_references_W = {{-0.8, 0.0}};
  data.nozzle_pan_rad = M_PI / 2;  // tilted toward +y: the arrow points up in the image
  cv::Mat image = black();
  draw_overlay(image, camera_, data);

  EXPECT_LT(colour_distance(at(image, expected_px(-0.3, 0.6)), style_.path_bgr), 40.0);
  EXPECT_GT(cv::norm(at(image, expected_px(-0.4, -0.6))), 30.0);  // a 1 px trail, anti-aliased
  EXPECT_LT(colour_distance(at(image, expected_px(0.8, 0.4)), style_.stagnation_bgr), 40.0);
  // The reference's ring, 9 px around it.
  EXPECT_LT(colour_distance(at(image, expected_px(-0.8, 0.0) + Eigen::Vector2d(9, 0)),
                            style_.current_reference_bgr),
            60.0);
  // The heading arrow: halfway along it is drawn, the same distance the other way is not.
  const double half = 0.5 * style_.heading_length_m;
  EXPECT_LT(colour_distance(at(image, expected_px(0.0, half)), style_.heading_bgr), 40.0);
  EXPECT_EQ(at(image, expected_px(0.0, -half)), cv::Vec3b(0, 0, 0));
  // Nothing where nothing was asked for.
  EXPECT_EQ(at(image, expected_px(0.5, -0.5)), cv::Vec3b(0, 0, 0));
}

TEST_F(OverlayTest, TimeLabelGoesTopLeft) {
  OverlayData data;
  data.time_s = 12.345;
  data.caption = "octagon";
  cv::Mat image = black();
  draw_overlay(image, camera_, data);
  const cv::Mat corner = image(cv::Rect(0, 0, 300, 80));
  const cv::Mat rest = image(cv::Rect(0, 100, 1024, 924));
  EXPECT_GT(cv::countNonZero(corner.reshape(1)), 200);
  EXPECT_EQ(cv::countNonZero(rest.reshape(1)), 0);
}

TEST_F(OverlayTest, BadInputIsAnInputError) {
  OverlayData data;
  cv::Mat small(512, 512, CV_8UC3, cv::Scalar::all(0));
  EXPECT_THROW(draw_overlay(small, camera_, data), InputError);
  cv::Mat image = black();
  data.stagnation_W = Eigen::Vector2d(std::numeric_limits<double>::quiet_NaN(), 0.0);
  EXPECT_THROW(draw_overlay(image, camera_, data), InputError);
  data = OverlayData{};
  data.zones.push_back({{0, 0}, -0.1, ""});
  EXPECT_THROW(draw_overlay(image, camera_, data), InputError);
  // Points far outside the view are skipped, not an error.
  data = OverlayData{};
  data.path_W = {{-100.0, 0.0}, {100.0, 0.0}};
  data.stagnation_W = Eigen::Vector2d(50.0, 50.0);
  EXPECT_NO_THROW(draw_overlay(image, camera_, data));
}

TEST(TrailHistory, KeepsTheLastPointsOfEachObject) {
  TrailHistory history(3);
  for (int k = 0; k < 5; ++k) history.push({{k, 0.0}, {0.0, k}});
  ASSERT_EQ(history.trails().size(), 2u);
  ASSERT_EQ(history.trails()[0].size(), 3u);
  EXPECT_EQ(history.trails()[0].front(), Eigen::Vector2d(2, 0));
  EXPECT_EQ(history.trails()[1].back(), Eigen::Vector2d(0, 4));
  EXPECT_THROW(history.push({{0.0, 0.0}}), InputError);
}

}  // namespace
}  // namespace airtwin
