#include "plots/batch_plot.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "common/errors.h"
#include "common/quantile.h"
#include "plots/canvas.h"

namespace airtwin::plots {
namespace {

constexpr int kTitleBaseline_px = 34;
const TextStyle kTitleStyle{0.75, 2, kBlack, 0, kWhite};
const TextStyle kCaptionStyle{0.5, 1, kBlack, 0, kWhite};
const TextStyle kNoteStyle{0.45, 1, kDarkGrey, 0, kWhite};
const cv::Scalar kBoxFill(222, 196, 176);  // light steel blue (BGR)
const cv::Scalar kBoxEdge(110, 60, 20);    // dark blue
const cv::Scalar kDot(100, 100, 100);
const cv::Scalar kOutlier(40, 40, 200);  // red
const cv::Scalar kBar(180, 130, 70);     // steel blue

void check_finite(const std::vector<double>& values, const std::string& what,
                  const std::string& path) {
  for (double v : values) {
    if (!std::isfinite(v)) {
      throw InputError(path + ": " + what + ": a value is not finite, cannot plot it");
    }
  }
}

// `text` in `style`, shrunk (to 0.35 at the smallest) and then shortened with ".." to fit width.
std::string fit_text(std::string text, TextStyle& style, int width_px) {
  while (text_size(text, style).width > width_px && style.scale > 0.35) style.scale *= 0.9;
  while (text.size() > 3 && text_size(text, style).width > width_px) {
    text = text.substr(0, text.size() - 3) + "..";
  }
  return text;
}

void draw_title(cv::Mat& img, const std::string& title) {
  TextStyle style = kTitleStyle;
  const std::string text = fit_text(title, style, img.cols - 40);
  draw_text(img, text, cv::Point2d(0.5 * img.cols, kTitleBaseline_px), HAlign::kCentre,
            VAlign::kBaseline, style);
}

cv::Point px(const PlotFrame& frame, double x, double y) {
  const cv::Point2d p = frame.to_px(x, y);
  return {static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y))};
}

// The y range of a plot of `lo`..`hi`: from min(0, lo), a little room above, never empty.
std::pair<double, double> value_range(double lo, double hi) {
  lo = std::min(0.0, lo);
  if (!(hi - lo > 1e-12 * std::max(1.0, std::abs(hi)))) hi = lo + 1.0;
  return {lo, hi + 0.05 * (hi - lo)};
}

// One box at x = centre (data units) of half-width half_px: dots, box, median, whiskers, outliers.
void draw_box(cv::Mat& img, const PlotFrame& frame, double centre, int half_px,
              const std::vector<double>& values) {
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  const double q1 = quantile_of_sorted(sorted, 0.25), q2 = quantile_of_sorted(sorted, 0.5),
               q3 = quantile_of_sorted(sorted, 0.75);
  const double reach = 1.5 * (q3 - q1);
  double low = q1, high = q3;  // the whiskers' ends: extreme values within reach of the box
  for (double v : sorted) {
    if (v >= q1 - reach) low = std::min(low, v);
    if (v <= q3 + reach) high = std::max(high, v);
  }
  const int u = px(frame, centre, 0.0).x;

  // The box (quartiles) tinted, the values over it, its frame and the median across it.
  const int top = px(frame, centre, q3).y, bottom = px(frame, centre, q1).y;
  const cv::Rect box(u - half_px, top, 2 * half_px + 1, std::max(1, bottom - top + 1));
  cv::Mat region = img(box & cv::Rect(0, 0, img.cols, img.rows));
  cv::Mat tint(region.size(), region.type(), kBoxFill);
  cv::addWeighted(region, 0.5, tint, 0.5, 0.0, region);
  // Every value as a dot, spread sideways by a low-discrepancy sequence (same input, same place).
  for (size_t k = 0; k < sorted.size(); ++k) {
    const double spread = std::fmod(0.5 + 0.6180339887498949 * static_cast<double>(k), 1.0) - 0.5;
    const cv::Point p(u + static_cast<int>(std::lround(1.4 * half_px * spread)),
                      px(frame, centre, sorted[k]).y);
    cv::circle(img, p, 2, kDot, cv::FILLED, cv::LINE_AA);
  }
  cv::rectangle(img, box, kBoxEdge, 1, cv::LINE_8);
  const int median_v = px(frame, centre, q2).y;
  cv::line(img, {u - half_px, median_v}, {u + half_px, median_v}, kBlack, 2, cv::LINE_8);
  // Whiskers with end caps.
  for (const auto& [from, to] : {std::pair{q3, high}, std::pair{q1, low}}) {
    const int v0 = px(frame, centre, from).y, v1 = px(frame, centre, to).y;
    cv::line(img, {u, v0}, {u, v1}, kBoxEdge, 1, cv::LINE_8);
    cv::line(img, {u - half_px / 2, v1}, {u + half_px / 2, v1}, kBoxEdge, 1, cv::LINE_8);
  }
  // Values beyond the whiskers, circled.
  for (double v : sorted) {
    if (v < low || v > high)
      cv::circle(img, {u, px(frame, centre, v).y}, 4, kOutlier, 1, cv::LINE_AA);
  }
}

}  // namespace

void write_box_plot_png(const std::string& title, const std::string& y_label,
                        const std::vector<BoxGroup>& groups, const std::string& path) {
  // The values: finite, and their range for the y axis.
  double lo = 0.0, hi = 0.0;
  bool any = false;
  for (const BoxGroup& g : groups) {
    check_finite(g.values, g.label, path);
    for (double v : g.values) {
      lo = any ? std::min(lo, v) : v;
      hi = any ? std::max(hi, v) : v;
      any = true;
    }
  }
  const auto [y_min, y_max] = value_range(lo, hi);

  // The canvas: about 110 px per group, the plot area inside the margins.
  const int n = std::max<int>(1, static_cast<int>(groups.size()));
  const int width = std::clamp(120 + 110 * n, 640, 2400), height = 560;
  cv::Mat img(height, width, CV_8UC3, kWhite);
  const cv::Rect area(100, 60, width - 130, height - 150);
  const PlotFrame frame(area, 0.0, static_cast<double>(n), y_min, y_max);
  const double group_px = area.width / static_cast<double>(n);
  const int half_px = std::clamp(static_cast<int>(0.3 * group_px), 3, 40);

  // A box per group, captions under the frame.
  for (size_t i = 0; i < groups.size(); ++i) {
    const double centre = static_cast<double>(i) + 0.5;
    const int u = px(frame, centre, y_min).x;
    if (groups[i].values.empty()) {
      draw_text(img, "no data", cv::Point2d(u, area.y + 0.5 * area.height), HAlign::kCentre,
                VAlign::kMiddle, kNoteStyle);
    } else {
      draw_box(img, frame, centre, half_px, groups[i].values);
    }
    TextStyle caption = kCaptionStyle, note = kNoteStyle;
    const int room = static_cast<int>(group_px) - 6;
    draw_text(img, fit_text(groups[i].label, caption, room),
              cv::Point2d(u, area.y + area.height + 12), HAlign::kCentre, VAlign::kTop, caption);
    draw_text(img, fit_text(groups[i].note, note, room), cv::Point2d(u, area.y + area.height + 36),
              HAlign::kCentre, VAlign::kTop, note);
  }
  draw_y_axis(img, frame, y_label);
  draw_title(img, title);
  write_png(img, path);
}

void write_histograms_png(const std::string& title, const std::vector<HistogramPanel>& panels,
                          const std::string& path) {
  constexpr int kPanelWidth_px = 560, kPanelHeight_px = 420, kTop_px = 50;
  const int n = std::max<int>(1, static_cast<int>(panels.size()));
  cv::Mat img(kTop_px + kPanelHeight_px, n * kPanelWidth_px, CV_8UC3, kWhite);
  for (size_t k = 0; k < panels.size(); ++k) {
    const HistogramPanel& p = panels[k];
    check_finite(p.values, p.title, path);
    const int x0 = static_cast<int>(k) * kPanelWidth_px;
    const cv::Rect area(x0 + 90, kTop_px + 56, kPanelWidth_px - 120, kPanelHeight_px - 136);
    TextStyle caption = kCaptionStyle, note = kNoteStyle;
    draw_text(img, fit_text(p.title, caption, kPanelWidth_px - 20),
              cv::Point2d(x0 + 0.5 * kPanelWidth_px, kTop_px + 14), HAlign::kCentre,
              VAlign::kBaseline, caption);
    draw_text(img, fit_text(p.note, note, kPanelWidth_px - 20),
              cv::Point2d(x0 + 0.5 * kPanelWidth_px, kTop_px + 36), HAlign::kCentre,
              VAlign::kBaseline, note);
    if (p.values.empty()) {
      draw_text(img, "no data", cv::Point2d(area.x + 0.5 * area.width, area.y + 0.5 * area.height),
                HAlign::kCentre, VAlign::kMiddle, kNoteStyle);
      continue;
    }

    // The bins: sqrt(n) of them (5 to 30) over the values' range; equal values get one bin.
    const auto [v_min, v_max] = std::minmax_element(p.values.begin(), p.values.end());
    double lo = *v_min, hi = *v_max;
    int bins = std::clamp(static_cast<int>(std::ceil(std::sqrt(p.values.size()))), 5, 30);
    if (!(hi - lo > 1e-4 * std::max(std::abs(lo), std::abs(hi)))) {
      const double half = lo != 0.0 ? 0.05 * std::abs(lo) : 0.5;
      lo -= half;
      hi += half;
      bins = 1;
    }
    std::vector<int> counts(bins, 0);
    for (double v : p.values) {
      const int b = static_cast<int>(std::floor((v - lo) / (hi - lo) * bins));
      ++counts[std::clamp(b, 0, bins - 1)];
    }

    // Bars on a count axis with whole-number ticks.
    const int most = *std::max_element(counts.begin(), counts.end());
    const PlotFrame frame(area, lo, hi, 0.0, std::max(5.0, std::ceil(1.15 * most)));
    for (int b = 0; b < bins; ++b) {
      if (counts[b] == 0) continue;
      const double x0b = lo + (hi - lo) * b / bins, x1b = lo + (hi - lo) * (b + 1) / bins;
      const cv::Rect bar(px(frame, x0b, counts[b]), px(frame, x1b, 0.0));
      cv::rectangle(img, bar, kBar, cv::FILLED, cv::LINE_8);
      cv::rectangle(img, bar, kBoxEdge, 1, cv::LINE_8);
    }
    draw_axes(img, frame, p.x_label, "runs");
  }
  draw_title(img, title);
  write_png(img, path);
}

}  // namespace airtwin::plots
