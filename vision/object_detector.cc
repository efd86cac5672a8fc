#include "vision/object_detector.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <opencv2/imgproc.hpp>

#include "common/errors.h"

namespace airtwin {
namespace {

constexpr double kPi = std::numbers::pi;

// Blob pixel weights, as the blob detector's centroid: brightness above the floor.
double pixel_weight(unsigned char grey, double floor) { return std::max(1.0, grey - floor); }

bool finite_positive(double v) { return std::isfinite(v) && v > 0; }

}  // namespace

const char* object_kind_name(ObjectKind kind) {
  return kind == ObjectKind::kTracer ? "tracer" : "cotton";
}

void ObjectDetectorOptions::validate() const {
  blobs.validate();
  circles.validate();
  if (!finite_positive(tracer_visible_diameter_m) || !finite_positive(cotton_visible_diameter_m) ||
      tracer_visible_diameter_m >= cotton_visible_diameter_m) {
    throw InputError(
        "object detector: visible diameters must be finite, > 0 and the tracer's smaller than the "
        "wad's");
  }
  if (!(std::isfinite(tracer_height_m) && tracer_height_m >= 0 && tracer_height_m < 1) ||
      !(std::isfinite(cotton_height_m) && cotton_height_m >= 0 && cotton_height_m < 1)) {
    throw InputError("object detector: heights must be finite and in [0, 1) m");
  }
  if (!rig_centre_W.allFinite() || !(std::isfinite(rig_mask_radius_m) && rig_mask_radius_m >= 0)) {
    throw InputError("object detector: the rig mask must be finite with a radius >= 0");
  }
}

ObjectDetector::ObjectDetector(const CalibratedCamera& camera, const ObjectDetectorOptions& options)
    : camera_(camera), options_(options), blob_detector_(options.blobs) {
  options_.validate();
  if (camera_.width_px <= 0 || camera_.height_px <= 0) {
    throw InputError("object detector: the camera has no image size");
  }
  // The rig's disc on the floor as a pixel disc (the camera looks straight down: a circle stays
  // one to well within a pixel).
  if (options_.rig_mask_radius_m > 0) {
    const Eigen::Vector3d c_W(options_.rig_centre_W.x(), options_.rig_centre_W.y(), 0.0);
    const auto centre = camera_.project(c_W);
    const auto edge = camera_.project(c_W + Eigen::Vector3d(options_.rig_mask_radius_m, 0, 0));
    if (centre && edge) {
      rig_mask_ = cv::Mat::zeros(camera_.height_px, camera_.width_px, CV_8UC1);
      cv::circle(rig_mask_,
                 cv::Point(static_cast<int>(std::lround(centre->x())),
                           static_cast<int>(std::lround(centre->y()))),
                 static_cast<int>(std::ceil((*edge - *centre).norm())), cv::Scalar(255),
                 cv::FILLED);
    }
  }
}

ObjectDetector::LocalScale ObjectDetector::local_scale(const Eigen::Vector2d& uv_px) const {
  // Metres per pixel at the kind's height, from two neighbouring pixels; the image centre's scale
  // if the lens model cannot take this pixel back.
  auto metres_per_px = [&](const Eigen::Vector2d& uv, double z) -> double {
    const auto a = camera_.point_at_height(uv - Eigen::Vector2d(0.5, 0), z);
    const auto b = camera_.point_at_height(uv + Eigen::Vector2d(0.5, 0), z);
    return a && b ? (*b - *a).norm() : 0.0;
  };
  const Eigen::Vector2d centre(camera_.K(0, 2), camera_.K(1, 2));
  double tracer = metres_per_px(uv_px, options_.tracer_height_m);
  if (!(tracer > 0)) tracer = metres_per_px(centre, options_.tracer_height_m);
  double cotton = metres_per_px(uv_px, options_.cotton_height_m);
  if (!(cotton > 0)) cotton = metres_per_px(centre, options_.cotton_height_m);
  AIRTWIN_DEMAND(tracer > 0 && cotton > 0);
  return {0.5 * options_.tracer_visible_diameter_m / tracer,
          0.5 * options_.cotton_visible_diameter_m / cotton};
}

std::vector<ObjectDetector::Seed> ObjectDetector::seeds_of(const Blob& blob,
                                                           const LocalScale& scale) {
  const double r_t = scale.tracer_radius_px, r_c = scale.cotton_radius_px;
  const double tracer_area = kPi * r_t * r_t, cotton_area = kPi * r_c * r_c;
  // Deeper than this (px from the background) is a wad's core: a tracer's disc is r_t deep.
  const double cotton_depth = r_t + 0.25 * (r_c - r_t);
  const double tracer_depth = 0.55 * r_t;
  const cv::Mat& grey = blob_detector_.grey();
  const cv::Rect image(0, 0, grey.cols, grey.rows);

  // The blob's own mask, framed by 2 px of background for the distance transform; `box` is
  // where it lies in the image (it may stick out of it by the frame).
  const cv::Rect box(blob.box.x - 2, blob.box.y - 2, blob.box.width + 4, blob.box.height + 4);
  cv::copyMakeBorder(blob.mask, remaining_, 2, 2, 2, 2, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::distanceTransform(remaining_, blob_depth_, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  auto depth_at = [&](const Eigen::Vector2d& uv) {
    const int u = static_cast<int>(std::lround(uv.x())) - box.x;
    const int v = static_cast<int>(std::lround(uv.y())) - box.y;
    if (u < 0 || v < 0 || u >= box.width || v >= box.height) return -1.0;
    return static_cast<double>(blob_depth_.at<float>(v, u));
  };

  // The deepest point of the blob within `radius` of `at` (ROI pixels) among those left.
  auto depth_near = [&](const cv::Point& at, double radius) {
    const int reach = static_cast<int>(std::ceil(radius));
    float deepest = 0.0f;
    for (int v = std::max(0, at.y - reach); v <= std::min(box.height - 1, at.y + reach); ++v) {
      const unsigned char* left = remaining_.ptr<unsigned char>(v);
      const float* d = blob_depth_.ptr<float>(v);
      for (int u = std::max(0, at.x - reach); u <= std::min(box.width - 1, at.x + reach); ++u) {
        if (left[u] && (u - at.x) * (u - at.x) + (v - at.y) * (v - at.y) <= radius * radius) {
          deepest = std::max(deepest, d[u]);
        }
      }
    }
    return static_cast<double>(deepest);
  };

  // The obvious singles: one tracer (tracer-sized, no wad's core), one wad (wad-sized, compact,
  // with a core). Their centre is the blob's centroid.
  const double depth = blob.peak_distance_px;
  if (blob.area_px <= 1.35 * tracer_area && depth < cotton_depth) {
    return depth >= tracer_depth ? std::vector<Seed>{{ObjectKind::kTracer, blob.centroid_px}}
                                 : std::vector<Seed>{};
  }
  if (blob.area_px <= 1.45 * cotton_area && depth >= cotton_depth && blob.elongation < 1.5 &&
      blob.circularity > 0.75) {
    return {{ObjectKind::kCotton, blob.centroid_px}};
  }

  // Touching objects. Tracers first, from the Hough transform on the blob's neighbourhood: a
  // circle centred on the blob, not in a wad's core, whose bright disc is about a tracer's.
  std::vector<Seed> seeds;
  if (options_.use_hough) {
    const cv::Rect around = (blob.box + cv::Size(20, 20) - cv::Point(10, 10)) & image;
    std::vector<DetectedCircle> circles = detect_circles(grey(around), options_.circles);
    std::sort(circles.begin(), circles.end(), [](const DetectedCircle& a, const DetectedCircle& b) {
      return a.bright_pixels > b.bright_pixels;
    });
    for (const DetectedCircle& c : circles) {
      const Eigen::Vector2d uv = c.centre_px + Eigen::Vector2d(around.x, around.y);
      const int u = static_cast<int>(std::lround(uv.x())),
                v = static_cast<int>(std::lround(uv.y()));
      if (!blob.box.contains({u, v}) ||
          !blob.mask.at<unsigned char>(v - blob.box.y, u - blob.box.x)) {
        continue;
      }
      const double d = depth_at(uv);
      if (d < tracer_depth || d >= cotton_depth) continue;
      if (c.bright_pixels > 1.25 * tracer_area || c.bright_pixels < 0.5 * tracer_area) continue;
      bool taken = false;
      for (const Seed& s : seeds) taken = taken || (s.centre_px - uv).norm() < 1.5 * r_t;
      if (!taken) seeds.push_back({ObjectKind::kTracer, uv});
    }
  }
  auto take_disc = [&](const Eigen::Vector2d& uv, double radius) {
    cv::circle(remaining_,
               cv::Point(static_cast<int>(std::lround(uv.x())) - box.x,
                         static_cast<int>(std::lround(uv.y())) - box.y),
               static_cast<int>(std::ceil(radius)), cv::Scalar(0), cv::FILLED);
  };
  for (const Seed& s : seeds) take_disc(s.centre_px, r_t + 1.0);
  // The deepest point of what is left (ROI pixels) and its depth.
  auto deepest_left = [&]() {
    cv::distanceTransform(remaining_, distance_, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    double peak = 0;
    cv::Point at;
    cv::minMaxLoc(distance_, nullptr, &peak, nullptr, &at);
    return std::pair<double, cv::Point>(peak, at);
  };

  // Then peel what is left by its distance transform: its deepest point is an object's core, a
  // wad's if the whole blob is deep around it (the piece left of a wad may be thinner than the
  // wad: a neighbour's disc took its edge), else a tracer's; the object's disc is taken away and
  // the next core looked for, until only edges are left.
  const int max_seeds = static_cast<int>(std::ceil(blob.area_px / tracer_area)) + 2;
  while (static_cast<int>(seeds.size()) < max_seeds) {
    const auto [peak, at] = deepest_left();
    if (peak < tracer_depth) break;
    const Eigen::Vector2d uv(at.x + box.x, at.y + box.y);
    if (depth_near(at, r_t) >= cotton_depth) {
      seeds.push_back({ObjectKind::kCotton, uv});
      take_disc(uv, r_c + 1.0);
    } else {
      seeds.push_back({ObjectKind::kTracer, uv});
      take_disc(uv, r_t + 1.0);
    }
  }
  // A blob of tracers alone holds as many as its area says (a tracer's area each; 0.7 of one
  // more counts as one): overlapping discs can leave a tracer too thin a piece to be peeled.
  // The missing ones go to the deepest points left, if any is more than a sliver.
  bool tracers_only = true;
  for (const Seed& s : seeds) tracers_only = tracers_only && s.kind == ObjectKind::kTracer;
  const int by_area = static_cast<int>(std::floor(blob.area_px / tracer_area + 0.3));
  while (tracers_only && !seeds.empty() && static_cast<int>(seeds.size()) < by_area) {
    const auto [peak, at] = deepest_left();
    if (peak < 0.4 * r_t) break;  // only slivers left
    const Eigen::Vector2d uv(at.x + box.x, at.y + box.y);
    seeds.push_back({ObjectKind::kTracer, uv});
    take_disc(uv, r_t + 1.0);
  }
  return seeds;
}

void ObjectDetector::refine(const Blob& blob, const LocalScale& scale, std::vector<Seed>& seeds,
                            std::vector<double>& areas) const {
  // Lloyd iterations over the blob's pixels: each pixel to the nearest seed in units of the
  // seed's radius, each seed to the brightness-weighted centroid of its pixels.
  const cv::Mat& grey = blob_detector_.grey();
  const double floor = blob_detector_.floor_grey();
  const size_t n = seeds.size();
  std::vector<double> inv_radius(n);
  for (size_t k = 0; k < n; ++k) {
    inv_radius[k] = 1.0 / (seeds[k].kind == ObjectKind::kTracer ? scale.tracer_radius_px
                                                                : scale.cotton_radius_px);
  }
  std::vector<Eigen::Vector3d> sums(n);
  for (int iteration = 0; iteration < 4; ++iteration) {
    std::fill(sums.begin(), sums.end(), Eigen::Vector3d::Zero());
    areas.assign(n, 0.0);
    for (int y = 0; y < blob.box.height; ++y) {
      const unsigned char* m = blob.mask.ptr<unsigned char>(y);
      const unsigned char* g = grey.ptr<unsigned char>(blob.box.y + y) + blob.box.x;
      const int v = blob.box.y + y;
      for (int x = 0; x < blob.box.width; ++x) {
        if (!m[x]) continue;
        const int u = blob.box.x + x;
        size_t best = 0;
        double best_d = 1e300;
        for (size_t k = 0; k < n; ++k) {
          const double du = u - seeds[k].centre_px.x(), dv = v - seeds[k].centre_px.y();
          const double d = (du * du + dv * dv) * inv_radius[k] * inv_radius[k];
          if (d < best_d) {
            best_d = d;
            best = k;
          }
        }
        const double w = pixel_weight(g[x], floor);
        sums[best] += Eigen::Vector3d(w, w * u, w * v);
        areas[best] += 1.0;
      }
    }
    for (size_t k = 0; k < n; ++k) {
      if (sums[k].x() > 0) seeds[k].centre_px = sums[k].tail<2>() / sums[k].x();
    }
  }
}

const std::vector<Detection>& ObjectDetector::detect(const cv::Mat& frame) {
  if (!frame.empty() && (frame.cols != camera_.width_px || frame.rows != camera_.height_px)) {
    throw InputError("object detector: frame is " + std::to_string(frame.cols) + " x " +
                     std::to_string(frame.rows) + " px, the camera's images are " +
                     std::to_string(camera_.width_px) + " x " + std::to_string(camera_.height_px));
  }
  blobs_ = blob_detector_.detect(frame, rig_mask_);
  detections_.clear();
  stats_ = DetectionStats{};
  stats_.blobs = static_cast<int>(blobs_.size());

  std::vector<Seed> seeds;
  std::vector<double> areas;
  for (size_t i = 0; i < blobs_.size(); ++i) {
    const Blob& blob = blobs_[i];
    // The rig, or an object whose image merges with the rig's: neither size nor centre holds.
    if (blob.touches_mask) {
      ++stats_.masked_blobs;
      continue;
    }
    const LocalScale scale = local_scale(blob.centroid_px);
    seeds = seeds_of(blob, scale);
    if (seeds.empty()) {
      ++stats_.empty_blobs;
      continue;
    }
    if (seeds.size() > 1) {
      ++stats_.merged_blobs;
      refine(blob, scale, seeds, areas);
    } else {
      areas.assign(1, blob.area_px);
    }
    // Each object to the floor through the camera, at its kind's height.
    for (size_t k = 0; k < seeds.size(); ++k) {
      const double z = seeds[k].kind == ObjectKind::kTracer ? options_.tracer_height_m
                                                            : options_.cotton_height_m;
      const auto p = camera_.point_at_height(seeds[k].centre_px, z);
      if (!p) {
        ++stats_.unplaced;
        continue;
      }
      Detection d;
      d.kind = seeds[k].kind;
      d.centre_px = seeds[k].centre_px;
      d.p_W = p->head<2>();
      d.area_px = areas[k];
      d.blob = static_cast<int>(i);
      d.objects_in_blob = static_cast<int>(seeds.size());
      d.at_border = blob.touches_border;
      detections_.push_back(d);
    }
  }
  std::sort(detections_.begin(), detections_.end(), [](const Detection& a, const Detection& b) {
    return a.centre_px.y() != b.centre_px.y() ? a.centre_px.y() < b.centre_px.y()
                                              : a.centre_px.x() < b.centre_px.x();
  });
  return detections_;
}

std::vector<Detection> detect_objects(const cv::Mat& frame, const CalibratedCamera& camera,
                                      const ObjectDetectorOptions& options) {
  ObjectDetector detector(camera, options);
  return detector.detect(frame);
}

}  // namespace airtwin
