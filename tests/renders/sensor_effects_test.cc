// Blur and sensor noise on synthetic images, measured against their definitions.

#include "renders/sensor_effects.h"

#include <gtest/gtest.h>

#include <cstring>

#include "common/errors.h"

namespace airtwin {
namespace {

bool same_bytes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() &&
         std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

TEST(SensorEffects, ZeroLevelsLeaveTheImageAlone) {
  cv::Mat image(64, 64, CV_8UC3, cv::Scalar(10, 120, 250));
  const cv::Mat before = image.clone();
  apply_sensor_effects(image, 0.0, 0.0, 1, 0);
  EXPECT_TRUE(same_bytes(image, before));
}

TEST(SensorEffects, NoiseHasTheAskedSigmaAndFollowsSeedAndFrame) {
  const cv::Mat grey(256, 256, CV_8UC3, cv::Scalar(128, 128, 128));
  cv::Mat a = grey.clone(), b = grey.clone(), c = grey.clone(), d = grey.clone();
  apply_sensor_effects(a, 4.0, 0.0, 9, 3);
  apply_sensor_effects(b, 4.0, 0.0, 9, 3);
  apply_sensor_effects(c, 4.0, 0.0, 10, 3);
  apply_sensor_effects(d, 4.0, 0.0, 9, 4);
  EXPECT_TRUE(same_bytes(a, b));
  EXPECT_FALSE(same_bytes(a, c));
  EXPECT_FALSE(same_bytes(a, d));
  // Sample statistics of 196 608 values: sigma within ~1 %, mean 128 (rounding adds 1/12 var).
  cv::Scalar mean, stddev;
  cv::meanStdDev(a.reshape(1), mean, stddev);
  EXPECT_NEAR(mean[0], 128.0, 0.05);
  EXPECT_NEAR(stddev[0], std::sqrt(16.0 + 1.0 / 12.0), 0.06);
  // Channels are independent: the correlation of B and G is ~0.
  std::vector<cv::Mat> ch;
  cv::split(a, ch);
  cv::Mat b32, g32;
  ch[0].convertTo(b32, CV_64F, 1.0, -128.0);
  ch[1].convertTo(g32, CV_64F, 1.0, -128.0);
  EXPECT_LT(std::abs(b32.dot(g32) / (b32.total() * 16.0)), 0.02);
}

TEST(SensorEffects, NoiseSaturatesInsteadOfWrapping) {
  cv::Mat white(64, 64, CV_8UC1, cv::Scalar(255)), black(64, 64, CV_8UC1, cv::Scalar(0));
  apply_sensor_effects(white, 20.0, 0.0, 1, 0);
  apply_sensor_effects(black, 20.0, 0.0, 1, 0);
  double lo, hi;
  cv::minMaxLoc(white, &lo, &hi);
  EXPECT_GT(lo, 150);  // a wrap-around would give values near 0
  cv::minMaxLoc(black, &lo, &hi);
  EXPECT_LT(hi, 100);
}

TEST(SensorEffects, BlurSpreadsAPointAsAGaussianOfTheAskedSigma) {
  cv::Mat image(61, 61, CV_8UC1, cv::Scalar(0));
  image.at<unsigned char>(30, 30) = 255;
  const double sigma = 1.5;
  cv::Mat blurred = image.clone();
  apply_sensor_effects(blurred, 0.0, sigma, 0, 0);
  // Second moment of the spread point: sigma^2 per axis (up to the 8-bit rounding).
  double mass = 0, m2 = 0;
  for (int r = 0; r < 61; ++r) {
    for (int c = 0; c < 61; ++c) {
      const double w = blurred.at<unsigned char>(r, c);
      mass += w;
      m2 += w * (c - 30) * (c - 30);
    }
  }
  EXPECT_NEAR(mass, 255.0, 255.0 * 0.08);
  EXPECT_NEAR(std::sqrt(m2 / mass), sigma, 0.15);
}

TEST(SensorEffects, RejectsBadLevels) {
  cv::Mat image(8, 8, CV_8UC3, cv::Scalar(0));
  EXPECT_THROW(apply_sensor_effects(image, -1.0, 0.0, 0, 0), InputError);
  EXPECT_THROW(apply_sensor_effects(image, 0.0, std::nan(""), 0, 0), InputError);
  cv::Mat floats(8, 8, CV_32FC1, cv::Scalar(0));
  EXPECT_THROW(apply_sensor_effects(floats, 1.0, 0.0, 0, 0), InputError);
}

}  // namespace
}  // namespace airtwin
