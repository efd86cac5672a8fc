#include "vision/circle_detector.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "common/errors.h"

namespace airtwin {

void CircleDetectorOptions::validate() const {
  auto finite_positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!finite_positive(min_radius_px) || !finite_positive(max_radius_px) ||
      min_radius_px > max_radius_px) {
    throw InputError("circle detector: radii must be finite, > 0 and min <= max");
  }
  if (!finite_positive(min_distance_px)) {
    throw InputError("circle detector: min_distance_px must be finite and > 0");
  }
  if (!finite_positive(edge_threshold) || !finite_positive(accumulator_threshold)) {
    throw InputError("circle detector: Hough thresholds must be finite and > 0");
  }
  if (bright_threshold < 0 || bright_threshold > 255) {
    throw InputError("circle detector: bright_threshold must be in [0, 255]");
  }
}

std::vector<DetectedCircle> detect_circles(const cv::Mat& frame, const CircleDetectorOptions& o) {
  o.validate();
  if (frame.empty()) throw InputError("circle detector: empty frame");
  cv::Mat grey;
  if (frame.type() == CV_8UC3) {
    cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
  } else if (frame.type() == CV_8UC1) {
    grey = frame;
  } else {
    throw InputError("circle detector: expected an 8-bit BGR or grey frame");
  }
  cv::Mat blurred;
  cv::GaussianBlur(grey, blurred, cv::Size(9, 9), 2.0);
  std::vector<cv::Vec3f> found;
  cv::HoughCircles(blurred, found, cv::HOUGH_GRADIENT, 1.0, o.min_distance_px, o.edge_threshold,
                   o.accumulator_threshold, static_cast<int>(std::floor(o.min_radius_px)),
                   static_cast<int>(std::ceil(o.max_radius_px)));

  std::vector<DetectedCircle> out;
  for (const cv::Vec3f& c : found) {
    // Sub-pixel centre: intensity-weighted centroid of the bright pixels within the radius plus
    // one pixel, weights grey - threshold (the rim, half lit, counts less than the cap).
    const double r = c[2] + 1.0;
    const int u0 = std::max(0, static_cast<int>(std::floor(c[0] - r)));
    const int u1 = std::min(grey.cols - 1, static_cast<int>(std::ceil(c[0] + r)));
    const int v0 = std::max(0, static_cast<int>(std::floor(c[1] - r)));
    const int v1 = std::min(grey.rows - 1, static_cast<int>(std::ceil(c[1] + r)));
    double sw = 0, su = 0, sv = 0;
    int n = 0;
    for (int v = v0; v <= v1; ++v) {
      const unsigned char* row = grey.ptr<unsigned char>(v);
      for (int u = u0; u <= u1; ++u) {
        const double du = u - c[0], dv = v - c[1];
        if (du * du + dv * dv > r * r || row[u] <= o.bright_threshold) continue;
        const double w = row[u] - o.bright_threshold;
        sw += w;
        su += w * u;
        sv += w * v;
        ++n;
      }
    }
    if (n == 0) continue;  // an edge ring without a bright cap: not a tracer
    DetectedCircle d;
    d.centre_px = {su / sw, sv / sw};
    d.radius_px = c[2];
    d.bright_pixels = n;
    out.push_back(d);
  }
  std::sort(out.begin(), out.end(), [](const DetectedCircle& a, const DetectedCircle& b) {
    return a.centre_px.y() != b.centre_px.y() ? a.centre_px.y() < b.centre_px.y()
                                              : a.centre_px.x() < b.centre_px.x();
  });
  return out;
}

}  // namespace airtwin
