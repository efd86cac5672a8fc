// Blob detection on drawn frames whose answers are known in closed form (a disc's area and
// centre, an ellipse's elongation), with sensor noise and blur, the ignore mask and the image's
// edge; then on a frame of the twin, where every object must give one blob.

#include "vision/blob_detector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <opencv2/imgproc.hpp>

#include "common/errors.h"
#include "renders/frame_renderer.h"
#include "tests/renders/render_scene.h"
#include "tests/vision/painted_shapes.h"

namespace airtwin {
namespace {

constexpr double kPi = std::numbers::pi;

// A floor of grey 85.
cv::Mat floor_image(int size = 200) { return cv::Mat(size, size, CV_8UC3, cv::Scalar(85, 85, 85)); }

using test::draw_ellipse;

void draw_disc(cv::Mat& image, const Eigen::Vector2d& centre, double radius) {
  draw_ellipse(image, centre, radius, radius);
}

// Seeded Gaussian noise, then a blur of sigma `blur` (px) first as the renderer does.
void degrade(cv::Mat& image, double noise_sigma, double blur_sigma, uint64_t seed) {
  if (blur_sigma > 0) cv::GaussianBlur(image, image, cv::Size(0, 0), blur_sigma);
  cv::Mat noise(image.size(), CV_32FC3);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
  cv::Mat f;
  image.convertTo(f, CV_32FC3);
  f += noise;
  f.convertTo(image, CV_8UC3);
}

TEST(BlobDetector, DiscAreaCentreAndShape) {
  cv::Mat image = floor_image();
  const Eigen::Vector2d centre(71.3, 120.6);
  const double radius = 7.5;
  draw_disc(image, centre, radius);
  const std::vector<Blob> blobs = detect_blobs(image);
  ASSERT_EQ(blobs.size(), 1u);
  const Blob& b = blobs[0];
  // Threshold at floor + 75 = 160: edge pixels count when ~45 % inside.
  EXPECT_NEAR(b.area_px, kPi * radius * radius, 0.05 * kPi * radius * radius);
  EXPECT_LT((b.centroid_px - centre).norm(), 0.1);
  EXPECT_NEAR(b.circularity, 1.0, 0.15);
  EXPECT_LT(b.elongation, 1.1);
  EXPECT_NEAR(b.peak_distance_px, radius, 1.0);
  EXPECT_FALSE(b.touches_border);
  EXPECT_FALSE(b.touches_mask);
}

TEST(BlobDetector, EllipseElongationIsTheAxisRatio) {
  cv::Mat image = floor_image();
  draw_ellipse(image, {100.3, 99.6}, 16, 8, kPi / 6);
  const std::vector<Blob> blobs = detect_blobs(image);
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_NEAR(blobs[0].elongation, 2.0, 0.1);
  EXPECT_NEAR(blobs[0].area_px, kPi * 16 * 8, 0.05 * kPi * 16 * 8);
  EXPECT_LT(blobs[0].circularity, 0.9);
}

TEST(BlobDetector, NoiseAndBlurKeepEveryDiscAndNothingElse) {
  // Tracer- and wad-sized discs on a noisy, blurred floor: the opening removes the specks, the
  // threshold stays > 10 sigma from the floor; the centres move by a fraction of a pixel.
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    cv::Mat image = floor_image(300);
    const std::vector<Eigen::Vector2d> centres = {
        {40.2, 50.7}, {150.5, 60.1}, {250.9, 240.3}, {80.0, 200.4}};
    const std::vector<double> radii = {5.2, 7.8, 5.2, 7.8};
    for (size_t i = 0; i < centres.size(); ++i) draw_disc(image, centres[i], radii[i]);
    degrade(image, 6.0, 1.0, seed);
    const std::vector<Blob> blobs = detect_blobs(image);
    ASSERT_EQ(blobs.size(), centres.size()) << "seed " << seed;
    for (size_t i = 0; i < centres.size(); ++i) {
      double best = 1e9;
      for (const Blob& b : blobs) best = std::min(best, (b.centroid_px - centres[i]).norm());
      EXPECT_LT(best, 0.35) << "seed " << seed << ", disc " << i;
    }
  }
}

TEST(BlobDetector, FloorLevelSetsTheThreshold) {
  // A brighter floor (grey 140): the threshold follows it, the discs are still found whole.
  cv::Mat image(200, 200, CV_8UC3, cv::Scalar(140, 140, 140));
  draw_disc(image, {60, 60}, 8);
  BlobDetector detector;
  const std::vector<Blob>& blobs = detector.detect(image);
  EXPECT_EQ(detector.floor_grey(), 140.0);
  EXPECT_EQ(detector.threshold_grey(), 215);
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_NEAR(blobs[0].area_px, kPi * 64, 0.1 * kPi * 64);
}

TEST(BlobDetector, IgnoreMaskAndImageEdge) {
  cv::Mat image = floor_image();
  draw_disc(image, {100, 100}, 8);  // half under the mask
  draw_disc(image, {30, 100}, 12);  // wholly under it: gone
  draw_disc(image, {2, 170}, 6);    // cut by the left edge
  draw_disc(image, {160, 40}, 6);   // free
  cv::Mat mask = cv::Mat::zeros(image.size(), CV_8UC1);
  cv::rectangle(mask, cv::Rect(0, 80, 100, 40), cv::Scalar(255), cv::FILLED);
  BlobDetector detector;
  const std::vector<Blob>& blobs = detector.detect(image, mask);
  ASSERT_EQ(blobs.size(), 3u);
  // Sorted by v: the free disc, the masked one, the cut one.
  EXPECT_FALSE(blobs[0].touches_mask);
  EXPECT_FALSE(blobs[0].touches_border);
  EXPECT_TRUE(blobs[1].touches_mask);
  EXPECT_LT(blobs[1].area_px, 0.6 * kPi * 64);  // its masked half is not counted
  EXPECT_TRUE(blobs[2].touches_border);
  // A second frame with the same detector gives the same blobs (scratch reuse).
  const std::vector<Blob> again = detector.detect(image, mask);
  ASSERT_EQ(again.size(), 3u);
  EXPECT_EQ(again[1].area_px, blobs[1].area_px);
}

TEST(BlobDetector, SpecksAndThinLinesAreNotBlobs) {
  // The opening (3 x 3) removes anything thinner than 3 px.
  cv::Mat image = floor_image();
  for (int k = 0; k < 40; ++k) image.at<cv::Vec3b>(10 + 4 * k, 20 + 3 * k) = {255, 255, 255};
  cv::line(image, cv::Point(150, 20), cv::Point(190, 180), cv::Scalar(255, 255, 255), 2);
  const std::vector<Blob> blobs = detect_blobs(image);
  EXPECT_TRUE(blobs.empty());
}

TEST(BlobDetector, BadInputIsAnInputError) {
  EXPECT_THROW(detect_blobs(cv::Mat()), InputError);
  EXPECT_THROW(detect_blobs(cv::Mat(10, 10, CV_32F)), InputError);
  BlobDetectorOptions o;
  o.threshold_above_floor = 0;
  EXPECT_THROW(BlobDetector{o}, InputError);
  o = {};
  o.opening_px = 0;
  EXPECT_THROW(BlobDetector{o}, InputError);
  BlobDetector detector;
  EXPECT_THROW(detector.detect(floor_image(100), cv::Mat::zeros(50, 50, CV_8UC1)), InputError);
}

TEST(BlobDetector, TwinFrameGivesOneBlobPerObjectPlusTheRig) {
  // Tracers ~86 px, wads ~150-240 px (docs/vision.md); the rig's parts stay within ~30 px of the
  // image centre.
  std::vector<ObjectSpec> objects = {{"t0", "tracer", {0.5, 0.3}, std::nullopt},
                                     {"t1", "tracer", {-0.7, -0.4}, std::nullopt},
                                     {"c0", "cotton", {-0.3, 0.8}, std::nullopt},
                                     {"c1", "cotton", {0.9, -0.9}, std::nullopt}};
  const testing::RenderScene s = testing::make_render_scene(objects);
  FrameRenderer renderer(s.model());
  const std::vector<Blob> blobs = detect_blobs(renderer.render(s.d(), 0));
  int tracers = 0, wads = 0, rig = 0;
  for (const Blob& b : blobs) {
    if ((b.centroid_px - Eigen::Vector2d(511.5, 511.5)).norm() < 40) {
      ++rig;
    } else if (b.area_px > 60 && b.area_px < 110) {
      ++tracers;
    } else if (b.area_px > 130 && b.area_px < 260) {
      ++wads;
    }
  }
  EXPECT_EQ(tracers, 2);
  EXPECT_EQ(wads, 2);
  EXPECT_EQ(static_cast<int>(blobs.size()), 4 + rig);
}

}  // namespace
}  // namespace airtwin
