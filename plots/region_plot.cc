#include "plots/region_plot.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "common/errors.h"
#include "plots/canvas.h"

namespace airtwin::plots {
namespace {

const cv::Scalar kMovedColour(60, 160, 40);    // green
const cv::Scalar kStillColour(175, 175, 175);  // grey
const cv::Scalar kTaskColour(200, 110, 30);    // blue: the scenario's path, zones, objects
constexpr int kPanelWidth_px = 620;
constexpr int kHeight_px = 720;

void check(const RegionPlot& plot, const std::string& path) {
  auto fail = [&](const std::string& what) {
    throw InputError(path + ": region picture: " + what);
  };
  if (!(std::isfinite(plot.extent_m) && plot.extent_m > 0.0)) fail("extent_m is not > 0");
  if (!(std::isfinite(plot.step_m) && plot.step_m > 0.0)) fail("step_m is not > 0");
  if (plot.directions_W.size() != plot.points_W.size()) {
    fail(std::to_string(plot.points_W.size()) + " points but " +
         std::to_string(plot.directions_W.size()) + " directions");
  }
  if (plot.panels.empty() || plot.panels.size() > 2) {
    fail("expected 1 or 2 panels, got " + std::to_string(plot.panels.size()));
  }
  for (const RegionPanel& panel : plot.panels) {
    if (panel.verdicts.size() != plot.points_W.size()) {
      fail("panel '" + panel.title + "' has " + std::to_string(panel.verdicts.size()) +
           " verdicts for " + std::to_string(plot.points_W.size()) + " pushes");
    }
  }
  for (size_t i = 0; i < plot.points_W.size(); ++i) {
    if (!plot.points_W[i].allFinite() || !plot.directions_W[i].allFinite()) {
      fail("push " + std::to_string(i) + " is not finite");
    }
  }
  for (const Eigen::Vector2d& p : plot.path_W) {
    if (!p.allFinite()) fail("a path vertex is not finite");
  }
  for (const RegionCircle& z : plot.zones) {
    if (!z.centre_W.allFinite() || !(std::isfinite(z.radius_m) && z.radius_m > 0.0)) {
      fail("a zone is not finite or its radius not > 0");
    }
  }
  for (const Eigen::Vector2d& p : plot.objects_W) {
    if (!p.allFinite()) fail("an object's position is not finite");
  }
}

// The scenario's task over the map.
void draw_task(cv::Mat& img, const PlotFrame& frame, const RegionPlot& plot) {
  for (size_t i = 1; i < plot.path_W.size(); ++i) {
    cv::line(img, frame.to_px(plot.path_W[i - 1]), frame.to_px(plot.path_W[i]), kTaskColour, 2,
             cv::LINE_AA);
  }
  for (const RegionCircle& z : plot.zones) {
    const int r = static_cast<int>(std::lround(z.radius_m * frame.px_per_x()));
    cv::circle(img, frame.to_px(z.centre_W), std::max(r, 1), kTaskColour, 2, cv::LINE_AA);
  }
  for (const Eigen::Vector2d& p : plot.objects_W) {
    cv::circle(img, frame.to_px(p), 4, kTaskColour, -1, cv::LINE_AA);
  }
}

void draw_panel(cv::Mat& img, int left_px, const RegionPlot& plot, const RegionPanel& panel) {
  const double lim = plot.extent_m + 0.5 * plot.step_m;
  const PlotFrame frame(cv::Rect(left_px + 80, 60, 500, 500), -lim, lim, -lim, lim);
  // The point below the nozzle.
  const cv::Point2d o = frame.to_px(0.0, 0.0);
  cv::line(img, o + cv::Point2d(-8, 0), o + cv::Point2d(8, 0), kBlack, 2, cv::LINE_AA);
  cv::line(img, o + cv::Point2d(0, -8), o + cv::Point2d(0, 8), kBlack, 2, cv::LINE_AA);
  // Still pushes first, so that the moving ones are drawn over them.
  for (const PushVerdict pass : {PushVerdict::kStill, PushVerdict::kMoved}) {
    for (size_t i = 0; i < plot.points_W.size(); ++i) {
      if (panel.verdicts[i] != pass) continue;
      const Eigen::Vector2d a = plot.points_W[i] + 0.08 * plot.step_m * plot.directions_W[i];
      const Eigen::Vector2d b = plot.points_W[i] + 0.42 * plot.step_m * plot.directions_W[i];
      if (pass == PushVerdict::kMoved) {
        cv::arrowedLine(img, frame.to_px(a), frame.to_px(b), kMovedColour, 2, cv::LINE_AA, 0, 0.35);
      } else {
        cv::line(img, frame.to_px(a), frame.to_px(b), kStillColour, 1, cv::LINE_AA);
      }
    }
  }
  draw_task(img, frame, plot);
  draw_axes(img, frame, "x (m)", "y (m)");
  TextStyle title;
  title.scale = 0.55;
  draw_text(img, panel.title, cv::Point2d(left_px + 330, 30), HAlign::kCentre, VAlign::kMiddle,
            title);
}

}  // namespace

void write_region_png(const RegionPlot& plot, const std::string& path) {
  check(plot, path);
  const int width = kPanelWidth_px * static_cast<int>(plot.panels.size());
  cv::Mat img(kHeight_px, width, CV_8UC3, kWhite);
  for (size_t k = 0; k < plot.panels.size(); ++k) {
    draw_panel(img, static_cast<int>(k) * kPanelWidth_px, plot, plot.panels[k]);
  }
  TextStyle legend;
  legend.scale = 0.45;
  const int y = kHeight_px - 95;
  cv::arrowedLine(img, cv::Point(40, y), cv::Point(70, y), kMovedColour, 2, cv::LINE_AA, 0, 0.35);
  draw_text(img, "the push moved the object;  + the point below the nozzle", cv::Point2d(80, y),
            HAlign::kLeft, VAlign::kMiddle, legend);
  cv::line(img, cv::Point(40, y + 22), cv::Point(70, y + 22), kStillColour, 1, cv::LINE_AA);
  draw_text(img, "it did not;  no line: the nozzle cannot put s there", cv::Point2d(80, y + 22),
            HAlign::kLeft, VAlign::kMiddle, legend);
  for (size_t k = 0; k < plot.caption.size(); ++k) {
    draw_text(img, plot.caption[k], cv::Point2d(40, y + 48 + 20 * static_cast<int>(k)),
              HAlign::kLeft, VAlign::kMiddle, legend);
  }
  write_png(img, path);
}

}  // namespace airtwin::plots
