#include "renders/overlay.h"

#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "common/errors.h"

namespace airtwin {
namespace {

// OpenCV's drawing takes integer points; 4 fractional bits keep the projection's sub-pixel
// position (pixel centres at integer coordinates, as in GroundTruthCamera).
constexpr int kShift = 4;
constexpr double kScale = 1 << kShift;
// Projected points farther than this outside the image are not drawn (and cannot overflow int).
constexpr double kMarginPx = 4096.0;

bool finite(const Eigen::Vector2d& p) { return std::isfinite(p.x()) && std::isfinite(p.y()); }

void require_finite(const Eigen::Vector2d& p, const char* what) {
  if (!finite(p)) throw InputError(std::string("overlay: ") + what + " is not finite");
}

class Projector {
 public:
  Projector(const GroundTruthCamera& camera) : camera_(camera) {}

  // The pixel of a floor point (m), or nothing when the camera does not see it usefully.
  std::optional<Eigen::Vector2d> pixel(const Eigen::Vector2d& p_W) const {
    const auto uv = camera_.project(Eigen::Vector3d(p_W.x(), p_W.y(), 0.0));
    if (!uv) return std::nullopt;
    if (uv->x() < -kMarginPx || uv->y() < -kMarginPx || uv->x() > camera_.width_px() + kMarginPx ||
        uv->y() > camera_.height_px() + kMarginPx) {
      return std::nullopt;
    }
    return uv;
  }
  static cv::Point fixed(const Eigen::Vector2d& uv) {
    return {static_cast<int>(std::lround(uv.x() * kScale)),
            static_cast<int>(std::lround(uv.y() * kScale))};
  }
  // Radius in px of a circle of radius_m around p_W on the floor.
  std::optional<double> radius_px(const Eigen::Vector2d& p_W, double radius_m) const {
    const auto c = pixel(p_W);
    const auto e = pixel(p_W + Eigen::Vector2d(radius_m, 0.0));
    if (!c || !e) return std::nullopt;
    return (*e - *c).norm();
  }

 private:
  const GroundTruthCamera& camera_;
};

void polyline(cv::Mat& bgr, const Projector& proj, const std::vector<Eigen::Vector2d>& points_W,
              const cv::Scalar& colour, int thickness) {
  for (size_t i = 1; i < points_W.size(); ++i) {
    const auto a = proj.pixel(points_W[i - 1]);
    const auto b = proj.pixel(points_W[i]);
    if (!a || !b) continue;
    cv::line(bgr, Projector::fixed(*a), Projector::fixed(*b), colour, thickness, cv::LINE_AA,
             kShift);
  }
}

// Text with a dark outline, readable on the light objects and the grey floor alike.
void label(cv::Mat& bgr, const std::string& text, cv::Point origin, double scale,
           const cv::Scalar& colour) {
  cv::putText(bgr, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), 4,
              cv::LINE_AA);
  cv::putText(bgr, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

// A translucent disc: the pixels inside are moved `alpha` of the way toward `colour`.
void tint_disc(cv::Mat& bgr, const Eigen::Vector2d& centre_px, double radius_px,
               const cv::Scalar& colour, double alpha) {
  const cv::Rect bounds(static_cast<int>(std::floor(centre_px.x() - radius_px)) - 1,
                        static_cast<int>(std::floor(centre_px.y() - radius_px)) - 1,
                        static_cast<int>(std::ceil(2 * radius_px)) + 3,
                        static_cast<int>(std::ceil(2 * radius_px)) + 3);
  const cv::Rect box = bounds & cv::Rect(0, 0, bgr.cols, bgr.rows);
  if (box.empty()) return;
  cv::Mat roi = bgr(box);
  cv::Mat mask = cv::Mat::zeros(box.size(), CV_8U);
  const Eigen::Vector2d local = centre_px - Eigen::Vector2d(box.x, box.y);
  cv::circle(mask, Projector::fixed(local), static_cast<int>(std::lround(radius_px * kScale)),
             cv::Scalar(255), cv::FILLED, cv::LINE_8, kShift);
  cv::Mat blended;
  cv::addWeighted(roi, 1.0 - alpha, cv::Mat(roi.size(), roi.type(), colour), alpha, 0.0, blended);
  blended.copyTo(roi, mask);
}

}  // namespace

void draw_overlay(cv::Mat& bgr, const GroundTruthCamera& camera, const OverlayData& data,
                  const OverlayStyle& style) {
  if (bgr.type() != CV_8UC3 || bgr.cols != camera.width_px() || bgr.rows != camera.height_px()) {
    throw InputError("overlay: the image must be 8-bit BGR of the camera's size (" +
                     std::to_string(camera.width_px()) + " x " +
                     std::to_string(camera.height_px()) + " px), got " + std::to_string(bgr.cols) +
                     " x " + std::to_string(bgr.rows) + " with " + std::to_string(bgr.channels()) +
                     " channel(s)");
  }
  // Every input finite before anything is drawn.
  for (const auto& p : data.path_W) require_finite(p, "a path point");
  for (const auto& p : data.path_references_W) require_finite(p, "a path reference");
  for (const auto& z : data.zones) {
    require_finite(z.centre_W, "a zone centre");
    if (!(std::isfinite(z.radius_m) && z.radius_m > 0)) {
      throw InputError("overlay: a zone radius must be a positive number");
    }
  }
  for (const auto& p : data.current_references_W) require_finite(p, "a current reference");
  if (data.stagnation_W) require_finite(*data.stagnation_W, "the stagnation point");
  if (data.nozzle_pan_rad && !std::isfinite(*data.nozzle_pan_rad)) {
    throw InputError("overlay: the nozzle pan is not finite");
  }
  require_finite(data.nozzle_base_W, "the nozzle base");
  for (const auto& trail : data.trails_W) {
    for (const auto& p : trail) require_finite(p, "a trail point");
  }
  if (data.time_s && !std::isfinite(*data.time_s)) {
    throw InputError("overlay: the time is not finite");
  }

  const Projector proj(camera);
  const int thick = style.line_thickness_px;

  // Zones: a light tint inside, the rim, the label to the right.
  for (const OverlayZone& zone : data.zones) {
    const auto c = proj.pixel(zone.centre_W);
    const auto r = proj.radius_px(zone.centre_W, zone.radius_m);
    if (!c || !r) continue;
    tint_disc(bgr, *c, *r, style.zone_bgr, style.zone_fill_alpha);
    cv::circle(bgr, Projector::fixed(*c), static_cast<int>(std::lround(*r * kScale)),
               style.zone_bgr, thick, cv::LINE_AA, kShift);
    if (!zone.label.empty()) {
      label(bgr, zone.label,
            cv::Point(static_cast<int>(c->x() + *r + 6), static_cast<int>(c->y() + 5)), 0.6,
            style.zone_bgr);
    }
  }

  // The reference path and its reference points.
  polyline(bgr, proj, data.path_W, style.path_bgr, thick);
  for (const auto& p : data.path_references_W) {
    if (const auto uv = proj.pixel(p)) {
      cv::circle(bgr, Projector::fixed(*uv), 3 << kShift, style.reference_dot_bgr, cv::FILLED,
                 cv::LINE_AA, kShift);
    }
  }

  // Where the objects have been.
  for (size_t j = 0; j < data.trails_W.size(); ++j) {
    const cv::Scalar& colour =
        style.trail_bgr.empty() ? style.path_bgr : style.trail_bgr[j % style.trail_bgr.size()];
    polyline(bgr, proj, data.trails_W[j], colour, 1);
  }

  // The current reference point(s): a ring with a cross.
  for (const auto& p : data.current_references_W) {
    const auto uv = proj.pixel(p);
    if (!uv) continue;
    const cv::Point c = Projector::fixed(*uv);
    cv::circle(bgr, c, 9 << kShift, style.current_reference_bgr, thick, cv::LINE_AA, kShift);
    const int arm = 5 << kShift;
    cv::line(bgr, c - cv::Point(arm, 0), c + cv::Point(arm, 0), style.current_reference_bgr, 1,
             cv::LINE_AA, kShift);
    cv::line(bgr, c - cv::Point(0, arm), c + cv::Point(0, arm), style.current_reference_bgr, 1,
             cv::LINE_AA, kShift);
  }

  // The stagnation point: an X.
  if (data.stagnation_W) {
    if (const auto uv = proj.pixel(*data.stagnation_W)) {
      const cv::Point c = Projector::fixed(*uv);
      const int arm = 8 << kShift;
      cv::line(bgr, c + cv::Point(-arm, -arm), c + cv::Point(arm, arm), style.stagnation_bgr,
               thick + 1, cv::LINE_AA, kShift);
      cv::line(bgr, c + cv::Point(-arm, arm), c + cv::Point(arm, -arm), style.stagnation_bgr,
               thick + 1, cv::LINE_AA, kShift);
    }
  }

  // The nozzle's heading: from the floor point below it toward the pan direction.
  if (data.nozzle_pan_rad) {
    const Eigen::Vector2d tip_W =
        data.nozzle_base_W +
        style.heading_length_m *
            Eigen::Vector2d(std::cos(*data.nozzle_pan_rad), std::sin(*data.nozzle_pan_rad));
    const auto a = proj.pixel(data.nozzle_base_W);
    const auto b = proj.pixel(tip_W);
    if (a && b) {
      cv::arrowedLine(bgr, Projector::fixed(*a), Projector::fixed(*b), style.heading_bgr, thick + 1,
                      cv::LINE_AA, kShift, 0.25);
    }
  }

  // Time and caption, top left.
  if (data.time_s) {
    char text[64];
    std::snprintf(text, sizeof(text), "t = %.2f s", *data.time_s);
    label(bgr, text, cv::Point(14, 34), 0.9, style.text_bgr);
  }
  if (!data.caption.empty()) {
    label(bgr, data.caption, cv::Point(14, data.time_s ? 66 : 34), 0.7, style.text_bgr);
  }
}

void TrailHistory::push(const std::vector<Eigen::Vector2d>& p_W) {
  if (trails_.empty()) trails_.resize(p_W.size());
  if (p_W.size() != trails_.size()) {
    throw InputError("trail history: got " + std::to_string(p_W.size()) + " positions, expected " +
                     std::to_string(trails_.size()));
  }
  for (size_t j = 0; j < p_W.size(); ++j) {
    std::vector<Eigen::Vector2d>& trail = trails_[j];
    trail.push_back(p_W[j]);
    if (trail.size() > max_points_) trail.erase(trail.begin());
  }
}

}  // namespace airtwin
