#pragma once
// Synthetic shapes for the detector tests, whose areas and centres are known exactly.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

namespace airtwin::test {

// A white ellipse (semi-axes a, b px, major axis at `angle` rad from +u) painted by area
// coverage (8 x 8 samples per pixel) on an 8-bit grey-valued BGR image: a pixel's grey goes from
// what it was toward 255 with the share of it inside, as a camera integrates light (never
// darker: overlapping shapes keep the brighter value). Pixels outside the image are skipped.
inline void draw_ellipse(cv::Mat& image, const Eigen::Vector2d& centre, double a, double b,
                         double angle = 0.0) {
  const double c = std::cos(angle), s = std::sin(angle);
  const int reach = static_cast<int>(std::max(a, b)) + 2;
  const int v0 = std::max(0, static_cast<int>(centre.y()) - reach);
  const int v1 = std::min(image.rows - 1, static_cast<int>(centre.y()) + reach);
  const int u0 = std::max(0, static_cast<int>(centre.x()) - reach);
  const int u1 = std::min(image.cols - 1, static_cast<int>(centre.x()) + reach);
  for (int v = v0; v <= v1; ++v) {
    for (int u = u0; u <= u1; ++u) {
      int inside = 0;
      for (int i = 0; i < 8; ++i) {
        for (int j = 0; j < 8; ++j) {
          const double du = u - 0.5 + (i + 0.5) / 8 - centre.x();
          const double dv = v - 0.5 + (j + 0.5) / 8 - centre.y();
          const double x = c * du + s * dv, y = -s * du + c * dv;
          inside += (x * x) / (a * a) + (y * y) / (b * b) <= 1.0;
        }
      }
      cv::Vec3b& p = image.at<cv::Vec3b>(v, u);
      p = cv::Vec3b::all(static_cast<unsigned char>(
          std::max<double>(p[0], std::lround(p[0] + (255.0 - p[0]) * inside / 64.0))));
    }
  }
}

}  // namespace airtwin::test
