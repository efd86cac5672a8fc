#include "plots/canvas.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/errors.h"

namespace airtwin::plots {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr int kTickLength_px = 6;
constexpr int kTickGap_px = 4;        // between a tick's end and its label
constexpr int kAxisLabelGap_px = 12;  // between tick labels and the axis label
const TextStyle kTickStyle{0.5, 1, kDarkGrey, 0, kWhite};
const TextStyle kAxisLabelStyle{0.62, 1, kBlack, 0, kWhite};

// Fraction of the way from lo to hi, computed on halves so that wide ranges do not overflow.
double fraction(double v, double lo, double hi) {
  return (0.5 * v - 0.5 * lo) / (0.5 * hi - 0.5 * lo);
}

}  // namespace

// ---- Plot frame ---------------------------------------------------------------------------------

PlotFrame::PlotFrame(cv::Rect area_px, double x_min, double x_max, double y_min, double y_max)
    : area_px_(area_px), x_min_(x_min), x_max_(x_max), y_min_(y_min), y_max_(y_max) {
  AIRTWIN_DEMAND(area_px.width >= 2 && area_px.height >= 2);
  AIRTWIN_DEMAND(std::isfinite(x_max - x_min) && x_max > x_min);
  AIRTWIN_DEMAND(std::isfinite(y_max - y_min) && y_max > y_min);
  px_per_x_ = (area_px.width - 1) / (x_max - x_min);
  px_per_y_ = (area_px.height - 1) / (y_max - y_min);
  AIRTWIN_DEMAND(std::isfinite(px_per_x_) && std::isfinite(px_per_y_));
}

cv::Point2d PlotFrame::to_px(double x, double y) const {
  return {area_px_.x + (x - x_min_) * px_per_x_, area_px_.y + (y_max_ - y) * px_per_y_};
}

double PlotFrame::x_at_column(double u) const { return x_min_ + (u - area_px_.x) / px_per_x_; }

double PlotFrame::y_at_row(double v) const { return y_max_ - (v - area_px_.y) / px_per_y_; }

bool PlotFrame::contains(const Eigen::Vector2d& p) const {
  return p.x() >= x_min_ && p.x() <= x_max_ && p.y() >= y_min_ && p.y() <= y_max_;
}

// ---- Ticks --------------------------------------------------------------------------------------

Ticks nice_ticks(double lo, double hi, int target_count) {
  const Ticks ends{{lo, hi}, hi - lo};
  const double span = hi - lo;
  if (!(span > 0) || !std::isfinite(span)) return ends;

  // The smallest step of 1, 2 or 5 x 10^k that gives at most about target_count ticks.
  const double raw = span / std::max(1, target_count);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10 * magnitude;
  for (const double m : {1.0, 2.0, 5.0}) {
    if (m * magnitude >= raw * (1 - 1e-9)) {
      step = m * magnitude;
      break;
    }
  }

  // The multiples of step inside [lo, hi]; none when double cannot resolve them.
  const double k_first = std::ceil(lo / step - 1e-9);
  const double k_last = std::floor(hi / step + 1e-9);
  if (!std::isfinite(k_first) || !std::isfinite(k_last) || k_last < k_first ||
      k_last - k_first > 1000 || (k_first + 1 == k_first)) {
    return ends;
  }
  Ticks ticks{{}, step};
  for (double k = k_first; k <= k_last; k += 1) {
    const double v = k * step;
    ticks.values.push_back(std::abs(v) < 1e-9 * step ? 0.0 : v);
  }
  return ticks;
}

std::string format_tick(double v, double step) {
  char text[64];
  const double decimals =
      std::isfinite(step) && step > 0 ? std::max(0.0, -std::floor(std::log10(step) + 1e-9)) : 0.0;
  // Fixed point for everyday magnitudes, %g for the rest.
  if (decimals <= 6 && std::abs(v) < 1e7) {
    std::snprintf(text, sizeof text, "%.*f", static_cast<int>(decimals), v);
  } else {
    std::snprintf(text, sizeof text, "%.3g", v);
  }
  // No "-0" or "-0.00".
  std::string s = text;
  if (s.size() > 1 && s[0] == '-' && s.find_first_not_of("0.", 1) == std::string::npos) {
    s.erase(0, 1);
  }
  return s;
}

// ---- Text ---------------------------------------------------------------------------------------

cv::Size text_size(const std::string& text, const TextStyle& style) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, style.scale, style.thickness, &baseline);
}

cv::Rect draw_text(cv::Mat& img, const std::string& text, cv::Point2d anchor, HAlign h, VAlign v,
                   const TextStyle& style) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, style.scale, style.thickness, &baseline);
  // The origin is the left end of the baseline.
  double x = anchor.x;
  if (h == HAlign::kCentre) x -= 0.5 * size.width;
  if (h == HAlign::kRight) x -= size.width;
  double y = anchor.y;
  if (v == VAlign::kTop) y += size.height;
  if (v == VAlign::kMiddle) y += 0.5 * size.height;
  const cv::Point origin(static_cast<int>(std::lround(x)), static_cast<int>(std::lround(y)));

  // Halo first, then the text over it.
  if (style.halo_px > 0) {
    cv::putText(img, text, origin, kFont, style.scale, style.halo_colour,
                style.thickness + 2 * style.halo_px, cv::LINE_AA);
  }
  cv::putText(img, text, origin, kFont, style.scale, style.colour, style.thickness, cv::LINE_AA);
  const int pad = style.halo_px + style.thickness;
  return {origin.x - pad, origin.y - size.height - pad, size.width + 2 * pad,
          size.height + baseline + 2 * pad};
}

void draw_text_upwards(cv::Mat& img, const std::string& text, cv::Point2d centre,
                       const TextStyle& style) {
  // Render horizontally on white, rotate, and darken the image with it.
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, style.scale, style.thickness, &baseline);
  constexpr int kPad = 2;
  cv::Mat flat(size.height + baseline + 2 * kPad, size.width + 2 * kPad, CV_8UC3,
               cv::Scalar::all(255));
  cv::putText(flat, text, cv::Point(kPad, kPad + size.height), kFont, style.scale, style.colour,
              style.thickness, cv::LINE_AA);
  cv::Mat upright;
  cv::rotate(flat, upright, cv::ROTATE_90_COUNTERCLOCKWISE);

  // Paste centred at `centre`, clipped to the image.
  const cv::Rect placed(static_cast<int>(std::lround(centre.x - 0.5 * upright.cols)),
                        static_cast<int>(std::lround(centre.y - 0.5 * upright.rows)), upright.cols,
                        upright.rows);
  const cv::Rect visible = placed & cv::Rect(0, 0, img.cols, img.rows);
  if (visible.empty()) return;
  cv::Mat target = img(visible);
  cv::min(target, upright(visible - placed.tl()), target);
}

// ---- Axes ---------------------------------------------------------------------------------------

namespace {

// y ticks left of the frame, labels right-aligned and centred on them, the y label rotated.
void draw_y_ticks_and_label(cv::Mat& img, const PlotFrame& frame, const std::string& y_label) {
  const cv::Rect& a = frame.area_px();
  const int left = a.x - 1;
  const Ticks yt = nice_ticks(frame.y_min(), frame.y_max(), 6);
  int widest = 0;
  for (const double y : yt.values) {
    const int v = static_cast<int>(std::lround(frame.to_px(frame.x_min(), y).y));
    cv::line(img, cv::Point(left - kTickLength_px, v), cv::Point(left, v), kBlack, 1, cv::LINE_8);
    const std::string label = format_tick(y, yt.step);
    widest = std::max(widest, text_size(label, kTickStyle).width);
    draw_text(img, label, cv::Point2d(left - kTickLength_px - kTickGap_px, v), HAlign::kRight,
              VAlign::kMiddle, kTickStyle);
  }
  const int y_label_height = text_size(y_label, kAxisLabelStyle).height;
  draw_text_upwards(img, y_label,
                    cv::Point2d(left - kTickLength_px - kTickGap_px - widest - kAxisLabelGap_px -
                                    0.5 * y_label_height,
                                a.y + 0.5 * (a.height - 1)),
                    kAxisLabelStyle);
}

}  // namespace

void draw_axes(cv::Mat& img, const PlotFrame& frame, const std::string& x_label,
               const std::string& y_label) {
  const cv::Rect& a = frame.area_px();
  const int left = a.x - 1, right = a.x + a.width, top = a.y - 1, bottom = a.y + a.height;
  cv::rectangle(img, cv::Point(left, top), cv::Point(right, bottom), kBlack, 1, cv::LINE_8);

  // x ticks below the frame, labels centred under them.
  const Ticks xt = nice_ticks(frame.x_min(), frame.x_max(), 6);
  const int label_height = text_size("0", kTickStyle).height;
  for (const double x : xt.values) {
    const int u = static_cast<int>(std::lround(frame.to_px(x, frame.y_min()).x));
    cv::line(img, cv::Point(u, bottom), cv::Point(u, bottom + kTickLength_px), kBlack, 1,
             cv::LINE_8);
    draw_text(img, format_tick(x, xt.step), cv::Point2d(u, bottom + kTickLength_px + kTickGap_px),
              HAlign::kCentre, VAlign::kTop, kTickStyle);
  }
  draw_text(img, x_label,
            cv::Point2d(a.x + 0.5 * (a.width - 1),
                        bottom + kTickLength_px + kTickGap_px + label_height + kAxisLabelGap_px),
            HAlign::kCentre, VAlign::kTop, kAxisLabelStyle);

  draw_y_ticks_and_label(img, frame, y_label);
}

void draw_y_axis(cv::Mat& img, const PlotFrame& frame, const std::string& y_label) {
  const cv::Rect& a = frame.area_px();
  cv::rectangle(img, cv::Point(a.x - 1, a.y - 1), cv::Point(a.x + a.width, a.y + a.height), kBlack,
                1, cv::LINE_8);
  draw_y_ticks_and_label(img, frame, y_label);
}

// ---- Colour scale -------------------------------------------------------------------------------

ColourScale::ColourScale(double lo, double hi, int colormap)
    : lo_(lo), hi_(hi), colormap_(colormap) {
  AIRTWIN_DEMAND(std::isfinite(lo) && std::isfinite(hi));
  // A degenerate range (constant field) widens upwards, or downwards at the top of double.
  if (!(hi - lo > 1e-9 * std::max(std::abs(lo), std::abs(hi)))) {
    const double width = std::max(1.0, 0.5 * std::abs(lo));
    if (std::isfinite(lo + width)) {
      hi_ = lo + width;
    } else {
      lo_ = lo - width;
      hi_ = lo;
    }
  }
  cv::Mat ramp(256, 1, CV_8UC1);
  for (int i = 0; i < 256; ++i) ramp.at<unsigned char>(i) = static_cast<unsigned char>(i);
  cv::applyColorMap(ramp, lut_, colormap);
}

unsigned char ColourScale::index(double v) const {
  const double t = fraction(v, lo_, hi_);
  if (!(t > 0)) return 0;
  if (t >= 1) return 255;
  return static_cast<unsigned char>(std::lround(255 * t));
}

cv::Vec3b ColourScale::colour(double v) const { return lut_.at<cv::Vec3b>(index(v)); }

void draw_colour_bar(cv::Mat& img, cv::Rect bar_px, const ColourScale& scale,
                     const std::string& label) {
  if (bar_px.width < 1 || bar_px.height < 2) return;
  // The bar itself: one colour per row, lo at the bottom.
  const double lo = scale.lo(), hi = scale.hi();
  const int n = bar_px.height;
  for (int r = 0; r < n; ++r) {
    const double f = static_cast<double>(n - 1 - r) / (n - 1);
    const cv::Vec3b c = scale.colour(lo * (1 - f) + hi * f);
    cv::line(img, cv::Point(bar_px.x, bar_px.y + r),
             cv::Point(bar_px.x + bar_px.width - 1, bar_px.y + r), cv::Scalar(c[0], c[1], c[2]), 1,
             cv::LINE_8);
  }
  const int left = bar_px.x - 1, right = bar_px.x + bar_px.width, top = bar_px.y - 1,
            bottom = bar_px.y + bar_px.height;
  cv::rectangle(img, cv::Point(left, top), cv::Point(right, bottom), kBlack, 1, cv::LINE_8);

  // Ticks and labels on the right.
  const Ticks ticks = nice_ticks(lo, hi, 8);
  int widest = 0;
  for (const double v : ticks.values) {
    const double f = std::clamp(fraction(v, lo, hi), 0.0, 1.0);
    const int row = static_cast<int>(std::lround(bar_px.y + (1 - f) * (n - 1)));
    cv::line(img, cv::Point(right, row), cv::Point(right + kTickLength_px, row), kBlack, 1,
             cv::LINE_8);
    const std::string text = format_tick(v, ticks.step);
    widest = std::max(widest, text_size(text, kTickStyle).width);
    draw_text(img, text, cv::Point2d(right + kTickLength_px + kTickGap_px, row), HAlign::kLeft,
              VAlign::kMiddle, kTickStyle);
  }
  const int label_height = text_size(label, kAxisLabelStyle).height;
  draw_text_upwards(img, label,
                    cv::Point2d(right + kTickLength_px + kTickGap_px + widest + kAxisLabelGap_px +
                                    0.5 * label_height,
                                bar_px.y + 0.5 * (n - 1)),
                    kAxisLabelStyle);
}

// ---- Sampling a rectilinear grid ----------------------------------------------------------------

GridCell locate(const Eigen::VectorXd& nodes, double q) {
  const Eigen::Index n = nodes.size();
  AIRTWIN_DEMAND(n >= 2);
  if (!(q > nodes[0])) return {0, 0.0};
  if (q >= nodes[n - 1]) return {n - 2, 1.0};
  const double* first = nodes.data();
  const Eigen::Index i = (std::upper_bound(first, first + n, q) - first) - 1;
  return {i, (q - nodes[i]) / (nodes[i + 1] - nodes[i])};
}

double bilinear(const Eigen::MatrixXd& values, const GridCell& cx, const GridCell& cy) {
  const double below = (1 - cx.t) * values(cy.i, cx.i) + cx.t * values(cy.i, cx.i + 1);
  const double above = (1 - cx.t) * values(cy.i + 1, cx.i) + cx.t * values(cy.i + 1, cx.i + 1);
  return (1 - cy.t) * below + cy.t * above;
}

void draw_scalar_map(cv::Mat& img, const PlotFrame& frame, const Eigen::VectorXd& x,
                     const Eigen::VectorXd& y, const Eigen::MatrixXd& values,
                     const ColourScale& scale) {
  AIRTWIN_DEMAND(img.type() == CV_8UC3);
  AIRTWIN_DEMAND(values.rows() == y.size() && values.cols() == x.size());
  const cv::Rect area = frame.area_px() & cv::Rect(0, 0, img.cols, img.rows);
  if (area.empty()) return;

  // Where each pixel column and row falls on the grid, once.
  std::vector<GridCell> columns(area.width), rows(area.height);
  for (int u = 0; u < area.width; ++u) columns[u] = locate(x, frame.x_at_column(area.x + u));
  for (int v = 0; v < area.height; ++v) rows[v] = locate(y, frame.y_at_row(area.y + v));

  // One colour per pixel centre.
  for (int v = 0; v < area.height; ++v) {
    cv::Vec3b* row = img.ptr<cv::Vec3b>(area.y + v) + area.x;
    for (int u = 0; u < area.width; ++u) {
      row[u] = scale.colour(bilinear(values, columns[u], rows[v]));
    }
  }
}

// ---- Output ------------------------------------------------------------------------------------

void write_png(const cv::Mat& img, const std::string& path) {
  std::vector<unsigned char> bytes;
  const std::vector<int> params = {cv::IMWRITE_PNG_COMPRESSION, 6};
  if (!cv::imencode(".png", img, bytes, params)) {
    throw InputError(path + ": PNG encoding failed");
  }
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) {
    throw InputError(path + ": cannot open file for writing: " + std::strerror(errno));
  }
  const size_t written = std::fwrite(bytes.data(), 1, bytes.size(), file);
  const int write_errno = errno;
  const bool closed = std::fclose(file) == 0;
  if (written != bytes.size() || !closed) {
    throw InputError(
        path + ": write failed: " + std::strerror(written != bytes.size() ? write_errno : errno));
  }
}

}  // namespace airtwin::plots
