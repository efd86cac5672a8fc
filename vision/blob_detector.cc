#include "vision/blob_detector.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <numbers>
#include <string>

#include <opencv2/imgproc.hpp>

#include "common/errors.h"

namespace airtwin {

void BlobDetectorOptions::validate() const {
  if (threshold_above_floor < 1 || threshold_above_floor > 254) {
    throw InputError("blob detector: threshold_above_floor must be in [1, 254]");
  }
  if (min_threshold < 1 || min_threshold > 254) {
    throw InputError("blob detector: min_threshold must be in [1, 254]");
  }
  if (opening_px < 1 || opening_px > 15) {
    throw InputError("blob detector: opening_px must be in [1, 15]");
  }
  if (!(std::isfinite(min_area_px) && min_area_px >= 1)) {
    throw InputError("blob detector: min_area_px must be finite and >= 1");
  }
}

double floor_grey_level(const cv::Mat& grey) {
  AIRTWIN_DEMAND(grey.type() == CV_8UC1 && !grey.empty());
  // A histogram of a sparse grid is enough for the median of a mostly uniform floor.
  std::array<int, 256> histogram{};
  int n = 0;
  for (int v = 0; v < grey.rows; v += 4) {
    const unsigned char* row = grey.ptr<unsigned char>(v);
    for (int u = 0; u < grey.cols; u += 4) {
      ++histogram[row[u]];
      ++n;
    }
  }
  int seen = 0;
  for (int level = 0; level < 256; ++level) {
    seen += histogram[level];
    if (2 * seen >= n) return level;
  }
  return 255;
}

BlobDetector::BlobDetector(const BlobDetectorOptions& options) : options_(options) {
  options_.validate();
  kernel_ = cv::getStructuringElement(cv::MORPH_RECT, {options_.opening_px, options_.opening_px});
}

const std::vector<Blob>& BlobDetector::detect(const cv::Mat& frame, const cv::Mat& ignore_mask) {
  // Grey image of the frame.
  if (frame.empty()) throw InputError("blob detector: empty frame");
  if (frame.type() == CV_8UC3) {
    cv::cvtColor(frame, grey_, cv::COLOR_BGR2GRAY);
  } else if (frame.type() == CV_8UC1) {
    frame.copyTo(grey_);
  } else {
    throw InputError("blob detector: expected an 8-bit BGR or grey frame");
  }
  const bool masked = !ignore_mask.empty();
  if (masked && (ignore_mask.type() != CV_8UC1 || ignore_mask.size() != frame.size())) {
    throw InputError("blob detector: the ignore mask must be CV_8UC1 and of the frame's size");
  }

  // Threshold against the floor's level, then open to remove specks of noise.
  floor_grey_ = floor_grey_level(grey_);
  threshold_ = std::clamp(static_cast<int>(floor_grey_) + options_.threshold_above_floor,
                          options_.min_threshold, 254);
  cv::threshold(grey_, binary_, threshold_, 255, cv::THRESH_BINARY);
  if (options_.opening_px > 1) {
    cv::morphologyEx(binary_, opened_, cv::MORPH_OPEN, kernel_);
  } else {
    binary_.copyTo(opened_);
  }

  // One blob per outer contour.
  cv::findContours(opened_, contours_, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  blobs_.clear();
  const double floor = floor_grey_;
  for (const std::vector<cv::Point>& contour : contours_) {
    Blob b;
    b.box = cv::boundingRect(contour);
    if (b.box.area() < options_.min_area_px) continue;
    // The blob's pixels: inside its contour and above the threshold (holes are not the blob's).
    b.mask = cv::Mat::zeros(b.box.size(), CV_8UC1);
    cv::drawContours(b.mask, std::vector<std::vector<cv::Point>>{contour}, 0, cv::Scalar(255),
                     cv::FILLED, cv::LINE_8, cv::noArray(), INT_MAX, -b.box.tl());
    b.mask &= opened_(b.box);
    // Pixels in the ignore mask are not the blob's, and tell that it reaches under it.
    if (masked) {
      const cv::Mat ignored = ignore_mask(b.box);
      for (int v = 0; v < b.box.height; ++v) {
        unsigned char* m = b.mask.ptr<unsigned char>(v);
        const unsigned char* i = ignored.ptr<unsigned char>(v);
        for (int u = 0; u < b.box.width; ++u) {
          if (m[u] && i[u]) {
            m[u] = 0;
            b.touches_mask = true;
          }
        }
      }
    }
    b.touches_border =
        b.box.x == 0 || b.box.y == 0 || b.box.br().x == grey_.cols || b.box.br().y == grey_.rows;

    // Area, brightness-weighted centroid and second moments in one pass.
    double sw = 0, su = 0, sv = 0, count = 0;
    double m_uu = 0, m_vv = 0, m_uv = 0, m_u = 0, m_v = 0;
    for (int y = 0; y < b.box.height; ++y) {
      const unsigned char* m = b.mask.ptr<unsigned char>(y);
      const unsigned char* g = grey_.ptr<unsigned char>(b.box.y + y) + b.box.x;
      const double v = b.box.y + y;
      for (int x = 0; x < b.box.width; ++x) {
        if (!m[x]) continue;
        const double u = b.box.x + x;
        const double w = std::max(1.0, g[x] - floor);
        sw += w;
        su += w * u;
        sv += w * v;
        count += 1;
        m_u += u;
        m_v += v;
        m_uu += u * u;
        m_vv += v * v;
        m_uv += u * v;
      }
    }
    if (count < options_.min_area_px) continue;  // small, or mostly in the ignore mask
    b.area_px = count;
    b.centroid_px = {su / sw, sv / sw};

    // Elongation from the central second moments (pixels as unit squares).
    const double cu = m_u / count, cv_ = m_v / count;
    const double a = m_uu / count - cu * cu + 1.0 / 12, c = m_vv / count - cv_ * cv_ + 1.0 / 12;
    const double bm = m_uv / count - cu * cv_;
    const double root = std::sqrt(0.25 * (a - c) * (a - c) + bm * bm);
    const double l1 = 0.5 * (a + c) + root, l2 = std::max(1e-9, 0.5 * (a + c) - root);
    b.elongation = std::sqrt(l1 / l2);

    // Perimeter, circularity and depth (distance transform with a background frame around).
    b.perimeter_px = cv::arcLength(contour, true);
    b.circularity = b.perimeter_px > 0
                        ? 4.0 * std::numbers::pi * b.area_px / (b.perimeter_px * b.perimeter_px)
                        : 0.0;
    cv::copyMakeBorder(b.mask, padded_, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
    cv::distanceTransform(padded_, distance_, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    double depth = 0;
    cv::minMaxLoc(distance_, nullptr, &depth);
    b.peak_distance_px = depth;
    blobs_.push_back(std::move(b));
  }
  std::sort(blobs_.begin(), blobs_.end(), [](const Blob& a, const Blob& b) {
    return a.centroid_px.y() != b.centroid_px.y() ? a.centroid_px.y() < b.centroid_px.y()
                                                  : a.centroid_px.x() < b.centroid_px.x();
  });
  return blobs_;
}

std::vector<Blob> detect_blobs(const cv::Mat& frame, const BlobDetectorOptions& options) {
  BlobDetector detector(options);
  return detector.detect(frame);
}

}  // namespace airtwin
