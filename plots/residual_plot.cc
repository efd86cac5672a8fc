#include "plots/residual_plot.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "plots/canvas.h"

namespace airtwin::plots {
namespace {

const cv::Scalar kRadial(200, 110, 30);     // blue: along the radial direction from s
const cv::Scalar kTangential(40, 60, 220);  // red: across it

// Residuals (cm) against one quantity: every sample as a faint dot, the bins' means as lines.
void scatter_panel(const DiscrepancyReport& r, const std::string& key, const std::string& x_label,
                   double (*value)(const ResidualSample&), const std::string& path) {
  cv::Mat img(560, 820, CV_8UC3, cv::Scalar(255, 255, 255));
  const std::vector<ResidualBin>& bins = r.residual_bins.at(key);
  const double x_lo = bins.front().lo, x_hi = bins.back().hi;
  double y_max = 1.0;
  std::vector<double> mags;
  for (const ResidualSample& s : r.residuals) {
    mags.push_back(100.0 * std::max(std::abs(s.radial_m), std::abs(s.tangential_m)));
  }
  if (!mags.empty()) {
    // The 98th percentile sets the scale, so a few outliers do not squash the rest.
    std::nth_element(mags.begin(), mags.begin() + static_cast<long>(0.98 * (mags.size() - 1)),
                     mags.end());
    y_max = std::max(1.0, mags[static_cast<size_t>(0.98 * (mags.size() - 1))]);
  }
  const PlotFrame frame(cv::Rect(90, 50, 690, 430), x_lo, x_hi, -y_max, y_max);
  cv::line(img, frame.to_px(x_lo, 0.0), frame.to_px(x_hi, 0.0), cv::Scalar(180, 180, 180), 1,
           cv::LINE_AA);
  for (const ResidualSample& s : r.residuals) {
    const double x = value(s);
    if (!(x >= x_lo && x <= x_hi)) continue;
    const double yr = std::clamp(100.0 * s.radial_m, -y_max, y_max);
    const double yt = std::clamp(100.0 * s.tangential_m, -y_max, y_max);
    cv::circle(img, frame.to_px(x, yr), 1, kRadial * 0.5 + cv::Scalar(128, 128, 128), -1);
    cv::circle(img, frame.to_px(x, yt), 1, kTangential * 0.5 + cv::Scalar(128, 128, 128), -1);
  }
  for (int which = 0; which < 2; ++which) {
    cv::Point2d last(-1, -1);
    for (const ResidualBin& b : bins) {
      if (b.n == 0) {
        last = {-1, -1};
        continue;
      }
      const double y = std::clamp(which == 0 ? b.radial_cm : b.tangential_cm, -y_max, y_max);
      const cv::Point2d p = frame.to_px(0.5 * (b.lo + b.hi), y);
      cv::circle(img, p, 4, which == 0 ? kRadial : kTangential, -1, cv::LINE_AA);
      if (last.x >= 0) cv::line(img, last, p, which == 0 ? kRadial : kTangential, 2, cv::LINE_AA);
      last = p;
    }
  }
  draw_axes(img, frame, x_label, "residual (cm)");
  TextStyle title;
  title.scale = 0.6;
  draw_text(img, "prediction - measurement: along the radial direction from s (blue), across (red)",
            {90, 30}, HAlign::kLeft, VAlign::kBaseline, title);
  write_png(img, path);
}

}  // namespace

void write_residual_plots(const DiscrepancyReport& r, const std::string& dir) {
  scatter_panel(
      r, "distance_from_s_m", "distance from s (m)",
      [](const ResidualSample& s) { return s.distance_m; }, dir + "/residuals_distance.png");
  scatter_panel(
      r, "alpha_deg", "alpha, direction from s (deg from downstream)",
      [](const ResidualSample& s) { return s.alpha_deg; }, dir + "/residuals_alpha.png");
  scatter_panel(
      r, "time_since_command_s", "time since the command changed (s)",
      [](const ResidualSample& s) { return s.since_change_s; },
      dir + "/residuals_time_since_command.png");
  scatter_panel(
      r, "speed_mps", "measured speed (m/s)", [](const ResidualSample& s) { return s.speed_mps; },
      dir + "/residuals_speed.png");

  // The floor: each sample at its position, coloured by the length of its residual.
  cv::Mat img(700, 760, CV_8UC3, cv::Scalar(255, 255, 255));
  const PlotFrame frame(cv::Rect(80, 40, 580, 580), -1.5, 1.5, -1.5, 1.5);
  double hi = 1.0;
  for (const ResidualSample& s : r.residuals) {
    hi = std::max(hi, 100.0 * std::hypot(s.radial_m, s.tangential_m));
  }
  const ColourScale scale(0.0, std::min(hi, 30.0), cv::COLORMAP_VIRIDIS);
  for (const ResidualSample& s : r.residuals) {
    if (!frame.contains(s.p_W)) continue;
    const cv::Vec3b c = scale.colour(100.0 * std::hypot(s.radial_m, s.tangential_m));
    cv::circle(img, frame.to_px(s.p_W), 2, cv::Scalar(c[0], c[1], c[2]), -1);
  }
  draw_axes(img, frame, "x (m)", "y (m)");
  draw_colour_bar(img, cv::Rect(680, 40, 18, 580), scale, "residual (cm)");
  write_png(img, dir + "/residuals_floor.png");
}

void write_correction_plot(const DiscrepancyReport& r, const std::string& path) {
  if (r.chosen_correction < 0) return;
  const ResidualCorrection& c = r.corrections.at(static_cast<size_t>(r.chosen_correction));
  // Cells with less than 2 % of the largest weight of data are grey: the correction there is
  // the smoother's shrinkage, not the data's.
  const double max_w = c.weight.empty() ? 0.0 : *std::max_element(c.weight.begin(), c.weight.end());
  const double min_w = 0.02 * max_w;
  double hi = 0.1;
  for (size_t k = 0; k < c.radial.size(); ++k) {
    if (c.weight[k] < min_w) continue;
    hi = std::max({hi, std::abs(c.radial[k]), std::abs(c.across[k])});
  }
  const ColourScale scale(-hi, hi, cv::COLORMAP_JET);
  TextStyle title;
  title.scale = 0.6;
  const std::string head = c.feature + " (bandwidth " + format_tick(c.bandwidth, 0.01) + " " +
                           c.unit + "): measured minus model acceleration (m/s^2)";
  if (c.ny > 1) {
    // Two maps: along the radial direction from s (left) and across it (right).
    cv::Mat img(620, 1280, CV_8UC3, cv::Scalar(255, 255, 255));
    const double x1 = c.x0 + (c.nx - 1) * c.step, y1 = c.y0 + (c.ny - 1) * c.step;
    const std::string xl = c.feature == "position_from_s" ? "downstream of s (m)" : "x (m)";
    const std::string yl = c.feature == "position_from_s" ? "left of s (m)" : "y (m)";
    for (int panel = 0; panel < 2; ++panel) {
      const PlotFrame frame(cv::Rect(90 + panel * 560, 60, 480, 480), c.x0, x1, c.y0, y1);
      const std::vector<double>& v = panel == 0 ? c.radial : c.across;
      for (int j = 0; j < c.ny; ++j) {
        for (int i = 0; i < c.nx; ++i) {
          const size_t k = static_cast<size_t>(j * c.nx + i);
          const cv::Point2d a = frame.to_px(c.x0 + (i - 0.5) * c.step, c.y0 + (j - 0.5) * c.step);
          const cv::Point2d b = frame.to_px(c.x0 + (i + 0.5) * c.step, c.y0 + (j + 0.5) * c.step);
          cv::Scalar colour(225, 225, 225);
          if (c.weight[k] >= min_w) {
            const cv::Vec3b col = scale.colour(v[k]);
            colour = cv::Scalar(col[0], col[1], col[2]);
          }
          cv::rectangle(img, cv::Rect(cv::Point(a), cv::Point(b)), colour, cv::FILLED);
        }
      }
      draw_axes(img, frame, xl, yl);
      draw_text(img, panel == 0 ? "radial (outward +)" : "across (counter-clockwise +)",
                {frame.area_px().x + 240.0, 52.0}, HAlign::kCentre, VAlign::kBaseline, title);
    }
    draw_colour_bar(img, cv::Rect(1210, 60, 18, 480), scale, "m/s^2");
    draw_text(img, head, {90, 25}, HAlign::kLeft, VAlign::kBaseline, title);
    write_png(img, path);
    return;
  }
  // One feature: both components against it; the data's weight as a grey band at the bottom.
  cv::Mat img(560, 820, CV_8UC3, cv::Scalar(255, 255, 255));
  const double x1 = c.x0 + (c.nx - 1) * c.step;
  const PlotFrame frame(cv::Rect(90, 50, 690, 430), c.x0, x1, -hi, hi);
  cv::line(img, frame.to_px(c.x0, 0.0), frame.to_px(x1, 0.0), cv::Scalar(180, 180, 180), 1,
           cv::LINE_AA);
  for (int which = 0; which < 2; ++which) {
    const std::vector<double>& v = which == 0 ? c.radial : c.across;
    cv::Point2d last(-1, -1);
    for (int i = 0; i < c.nx; ++i) {
      if (c.weight[static_cast<size_t>(i)] < min_w) {
        last = {-1, -1};
        continue;
      }
      const cv::Point2d p = frame.to_px(c.x0 + i * c.step, v[static_cast<size_t>(i)]);
      if (last.x >= 0) cv::line(img, last, p, which == 0 ? kRadial : kTangential, 2, cv::LINE_AA);
      last = p;
    }
  }
  draw_axes(img, frame, c.feature + " (" + c.unit + ")", "m/s^2");
  draw_text(img, head + ": radial (blue), across (red)", {90, 30}, HAlign::kLeft, VAlign::kBaseline,
            title);
  write_png(img, path);
}

}  // namespace airtwin::plots
