#include "plots/field_plot.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "common/errors.h"
#include "common/text.h"
#include "plots/canvas.h"

namespace airtwin::plots {
namespace {

// Layout: the map is fitted into a square box, the colour bar to its right, the title above and
// the legend below.
const cv::Rect kMapBox_px(100, 76, 712, 712);
constexpr int kColourBarLeft_px = 852;
constexpr int kColourBarWidth_px = 24;
constexpr double kMaxAspect = 4.0;
constexpr int kTitleBaseline_px = 34;
constexpr int kSubtitleBaseline_px = 58;
constexpr int kLegendMiddle_px = 872;

// Arrows: about one per kArrowSpacing_px, the fastest kArrowFill of the spacing long, none
// shorter than kArrowMin_px.
constexpr double kArrowSpacing_px = 40.0;
constexpr double kArrowFill = 0.9;
constexpr double kArrowMin_px = 5.0;

// Marks.
constexpr int kShift = 4;  // sub-pixel bits for OpenCV drawing
constexpr double kMarkRadius_px = 9.0;
const cv::Scalar kStagnationRed(40, 40, 230);
const cv::Scalar kProjectionMagenta(230, 50, 230);
const cv::Scalar kOutline(30, 30, 30);
const TextStyle kMarkLabelStyle{0.8, 2, kWhite, 2, kBlack};
const TextStyle kLegendStyle{0.5, 1, kBlack, 0, kWhite};
const TextStyle kTitleStyle{0.8, 2, kBlack, 0, kWhite};
const TextStyle kSubtitleStyle{0.5, 1, kDarkGrey, 0, kWhite};

// A position in OpenCV's fixed point with kShift fractional bits.
cv::Point fixed(cv::Point2d p) {
  constexpr double kScale = 1 << kShift;
  return {static_cast<int>(std::lround(p.x * kScale)), static_cast<int>(std::lround(p.y * kScale))};
}

cv::Point2d unit(cv::Point2d d) {
  const double n = std::hypot(d.x, d.y);
  return n > 0 ? d / n : cv::Point2d(0, 0);
}

// ---- Validation ---------------------------------------------------------------------------------

// An axis: at least 2 finite, strictly ascending nodes spanning a drawable range.
void check_axis(const Eigen::VectorXd& q, const std::string& name, const std::string& where) {
  const Eigen::Index n = q.size();
  if (n < 2) {
    throw InputError(where + ": grid." + name + " has " + std::to_string(n) + " node" +
                     (n == 1 ? "" : "s") + "; at least 2 per axis are needed");
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!std::isfinite(q[i])) {
      throw InputError(where + ": grid." + name + "[" + std::to_string(i) + "] is " +
                       format_short(q[i]) + "; coordinates must be finite");
    }
    if (i > 0 && !(q[i] > q[i - 1])) {
      throw InputError(where + ": grid." + name + " must be strictly ascending, but " + name + "[" +
                       std::to_string(i) + "] = " + format_short(q[i]) + " follows " + name + "[" +
                       std::to_string(i - 1) + "] = " + format_short(q[i - 1]));
    }
  }
  const double span = q[n - 1] - q[0];
  if (!std::isfinite(span) || !std::isfinite(kMapBox_px.width / span)) {
    throw InputError(where + ": grid." + name + " spans " + format_short(span) +
                     " m, which cannot be drawn");
  }
}

// Per-node values: ny x nx, all finite.
void check_values(const Eigen::MatrixXd& m, const std::string& name, const VectorFieldGrid& grid,
                  const std::string& where) {
  const Eigen::Index ny = grid.y.size(), nx = grid.x.size();
  if (m.rows() != ny || m.cols() != nx) {
    throw InputError(where + ": grid." + name + " is " + std::to_string(m.rows()) + " x " +
                     std::to_string(m.cols()) + " but y has " + std::to_string(ny) + " and x has " +
                     std::to_string(nx) + " nodes; expected " + std::to_string(ny) + " x " +
                     std::to_string(nx) + " (rows = y index, columns = x index)");
  }
  for (Eigen::Index i = 0; i < nx; ++i) {
    for (Eigen::Index j = 0; j < ny; ++j) {
      if (!std::isfinite(m(j, i))) {
        throw InputError(where + ": grid." + name + "(" + std::to_string(j) + ", " +
                         std::to_string(i) + ") at (x, y) = (" + format_short(grid.x[i]) + ", " +
                         format_short(grid.y[j]) + ") m is " + format_short(m(j, i)) +
                         "; field values must be finite");
      }
    }
  }
}

void check_marks(const FieldMarks& marks, const std::string& where) {
  if (!marks.stagnation_W.allFinite()) {
    throw InputError(where + ": the stagnation point s = (" + format_short(marks.stagnation_W.x()) +
                     ", " + format_short(marks.stagnation_W.y()) + ") m must be finite");
  }
  if (!marks.projection_W.allFinite()) {
    throw InputError(where + ": the projection point c = (" + format_short(marks.projection_W.x()) +
                     ", " + format_short(marks.projection_W.y()) + ") m must be finite");
  }
  if (!(marks.speed_max_mps >= 0) || !std::isfinite(marks.speed_max_mps)) {
    throw InputError(where + ": speed_max_mps must be a finite speed >= 0 (0: automatic), got " +
                     format_short(marks.speed_max_mps));
  }
}

// ---- Layout -------------------------------------------------------------------------------------

// The map's pixel rectangle in kMapBox_px: equal scale on both axes (aspect clamped), centred.
cv::Rect map_area_px(const VectorFieldGrid& grid) {
  const double width_m = grid.x[grid.x.size() - 1] - grid.x[0];
  const double height_m = grid.y[grid.y.size() - 1] - grid.y[0];
  const double aspect = std::clamp(width_m / height_m, 1 / kMaxAspect, kMaxAspect);
  int width = kMapBox_px.width, height = kMapBox_px.height;
  if (aspect >= 1) {
    height = static_cast<int>(std::lround((width - 1) / aspect)) + 1;
  } else {
    width = static_cast<int>(std::lround((height - 1) * aspect)) + 1;
  }
  return {kMapBox_px.x + (kMapBox_px.width - width) / 2,
          kMapBox_px.y + (kMapBox_px.height - height) / 2, width, height};
}

// ---- Arrows -------------------------------------------------------------------------------------

// A white arrow with a dark outline (visible on both ends of the colour map), centred at `centre`
// along unit direction `dir`, length_px long.
void draw_arrow(cv::Mat& img, cv::Point2d centre, cv::Point2d dir, double length_px) {
  const cv::Point2d tip = centre + 0.5 * length_px * dir;
  const cv::Point2d tail = centre - 0.5 * length_px * dir;
  const double head = std::min(std::clamp(0.3 * length_px, 4.0, 8.0), 0.7 * length_px);
  const cv::Point2d base = tip - head * dir;
  const cv::Point2d side = 0.5 * head * cv::Point2d(-dir.y, dir.x);
  const std::array<cv::Point, 3> corners = {fixed(tip), fixed(base + side), fixed(base - side)};

  // Outline first, then the white arrow over it.
  cv::line(img, fixed(tail), fixed(base), kOutline, 3, cv::LINE_AA, kShift);
  cv::polylines(img, std::vector<cv::Point>(corners.begin(), corners.end()), true, kOutline, 2,
                cv::LINE_AA, kShift);
  cv::line(img, fixed(tail), fixed(base), kWhite, 1, cv::LINE_AA, kShift);
  cv::fillConvexPoly(img, corners.data(), 3, kWhite, cv::LINE_AA, kShift);
}

// Arrows along (vx, vy) at the centres of a regular grid of cells over the map, interpolated
// bilinearly; length proportional to speed, the fastest filling kArrowFill of a cell.
void draw_arrows(cv::Mat& img, const PlotFrame& frame, const VectorFieldGrid& grid) {
  const cv::Rect& a = frame.area_px();
  const int nu = std::max(1, static_cast<int>(std::lround(a.width / kArrowSpacing_px)));
  const int nv = std::max(1, static_cast<int>(std::lround(a.height / kArrowSpacing_px)));
  const double du = static_cast<double>(a.width) / nu, dv = static_cast<double>(a.height) / nv;

  // Sample the velocity at every cell centre; find the fastest.
  struct Sample {
    cv::Point2d centre_px;
    double vx, vy, speed;
  };
  std::vector<Sample> samples;
  samples.reserve(static_cast<size_t>(nu) * nv);
  double fastest = 0.0;
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const cv::Point2d centre(a.x - 0.5 + (i + 0.5) * du, a.y - 0.5 + (j + 0.5) * dv);
      const GridCell cx = locate(grid.x, frame.x_at_column(centre.x));
      const GridCell cy = locate(grid.y, frame.y_at_row(centre.y));
      const double vx = bilinear(grid.vx, cx, cy), vy = bilinear(grid.vy, cx, cy);
      const double speed = std::hypot(vx, vy);
      samples.push_back({centre, vx, vy, speed});
      fastest = std::max(fastest, speed);
    }
  }
  if (!(fastest > 0) || !std::isfinite(fastest)) return;

  // Draw all but the near-zero ones; image rows grow downwards, so y flips.
  const double longest_px = kArrowFill * std::min(du, dv);
  for (const Sample& s : samples) {
    const double length_px = longest_px * (s.speed / fastest);
    if (!(length_px >= kArrowMin_px)) continue;
    const cv::Point2d dir =
        unit({s.vx / s.speed * frame.px_per_x(), -s.vy / s.speed * frame.px_per_y()});
    draw_arrow(img, s.centre_px, dir, length_px);
  }
}

// ---- Marks --------------------------------------------------------------------------------------

// s: a red disc in a white ring with a dark edge; `size` scales it (1 on the map).
void draw_stagnation_symbol(cv::Mat& img, cv::Point2d p, double size = 1.0) {
  const double r = size * kMarkRadius_px;
  for (const auto& [radius, colour] : {std::pair{r + 1, kOutline}, std::pair{r, kWhite},
                                       std::pair{r - 2.5 * size, kStagnationRed}}) {
    cv::circle(img, fixed(p), static_cast<int>(std::lround(radius * (1 << kShift))), colour,
               cv::FILLED, cv::LINE_AA, kShift);
  }
}

// c: a magenta cross with a dark outline (unlike the white arrows); `size` scales it.
void draw_projection_symbol(cv::Mat& img, cv::Point2d p, double size = 1.0) {
  const double arm = size * (kMarkRadius_px + 2);
  for (const cv::Scalar& colour : {kOutline, kProjectionMagenta}) {
    const int thickness = static_cast<int>(std::lround(size * (colour == kOutline ? 7 : 3)));
    cv::line(img, fixed(p + cv::Point2d(-arm, -arm)), fixed(p + cv::Point2d(arm, arm)), colour,
             thickness, cv::LINE_AA, kShift);
    cv::line(img, fixed(p + cv::Point2d(-arm, arm)), fixed(p + cv::Point2d(arm, -arm)), colour,
             thickness, cv::LINE_AA, kShift);
  }
}

// A pointer at the edge of the map towards an off-map point: a triangle filled with `fill`.
void draw_pointer(cv::Mat& img, cv::Point2d at, cv::Point2d dir, const cv::Scalar& fill) {
  const cv::Point2d side(-dir.y * 9, dir.x * 9);
  const std::array<cv::Point, 3> corners = {fixed(at + 11 * dir), fixed(at - 7 * dir + side),
                                            fixed(at - 7 * dir - side)};
  cv::fillConvexPoly(img, corners.data(), 3, fill, cv::LINE_AA, kShift);
  cv::polylines(img, std::vector<cv::Point>(corners.begin(), corners.end()), true, kOutline, 2,
                cv::LINE_AA, kShift);
}

struct Mark {
  std::string name;  // "s" or "c"
  Eigen::Vector2d p_W;
  bool on_map = false;
  cv::Point2d at_px = {};      // the point itself, or where its pointer sits
  cv::Point2d label_dir = {};  // from at_px towards the label
};

// The label's box when its centre sits `distance` px from `at` along `dir`.
cv::Rect label_box(const std::string& text, cv::Point2d at, cv::Point2d dir, double distance) {
  const cv::Size size = text_size(text, kMarkLabelStyle);
  const int pad = kMarkLabelStyle.halo_px + kMarkLabelStyle.thickness;
  const cv::Point2d centre = at + distance * dir;
  return {static_cast<int>(std::lround(centre.x - 0.5 * size.width)) - pad,
          static_cast<int>(std::lround(centre.y - 0.5 * size.height)) - pad, size.width + 2 * pad,
          size.height + 2 * pad};
}

// The distance from a mark's centre to its label's centre.
double label_distance(const std::string& text) {
  const cv::Size size = text_size(text, kMarkLabelStyle);
  return kMarkRadius_px + 8 + 0.5 * std::hypot(size.width, size.height);
}

// Labels s and c beside their marks: the preferred side first, then the others, keeping inside
// the map.
void draw_mark_label(cv::Mat& img, const PlotFrame& frame, const Mark& m) {
  const double distance = label_distance(m.name);
  const cv::Point2d d = m.label_dir;
  const std::array<cv::Point2d, 4> tries = {d, -d, cv::Point2d(-d.y, d.x), cv::Point2d(d.y, -d.x)};
  cv::Point2d chosen = d;
  for (const cv::Point2d& t : tries) {
    const cv::Rect box = label_box(m.name, m.at_px, t, distance);
    if ((box & frame.area_px()) == box) {
      chosen = t;
      break;
    }
  }
  draw_text(img, m.name, m.at_px + distance * chosen, HAlign::kCentre, VAlign::kMiddle,
            kMarkLabelStyle);
}

// s and c: symbols and labels on the map, or pointers at its edge when they lie outside.
void draw_marks(cv::Mat& img, const PlotFrame& frame, std::array<Mark, 2>& marks) {
  const cv::Rect& a = frame.area_px();
  const cv::Point2d centre_px(a.x + 0.5 * (a.width - 1), a.y + 0.5 * (a.height - 1));
  const Eigen::Vector2d centre_W(0.5 * (frame.x_min() + frame.x_max()),
                                 0.5 * (frame.y_min() + frame.y_max()));
  constexpr double kInset_px = 18;
  const double half_u = std::max(1.0, 0.5 * (a.width - 1) - kInset_px);
  const double half_v = std::max(1.0, 0.5 * (a.height - 1) - kInset_px);

  // Where each mark goes: at its pixel, or where the ray from the map's centre towards it meets
  // the inset edge (computed on the scaled direction, so far-away points do not overflow).
  std::array<cv::Point2d, 2> outward;
  for (size_t k = 0; k < marks.size(); ++k) {
    Mark& m = marks[k];
    m.on_map = frame.contains(m.p_W);
    if (m.on_map) {
      m.at_px = frame.to_px(m.p_W);
      continue;
    }
    const Eigen::Vector2d d_W = m.p_W - centre_W;
    const double big = d_W.cwiseAbs().maxCoeff();
    const cv::Point2d dir =
        unit({d_W.x() / big * frame.px_per_x(), -d_W.y() / big * frame.px_per_y()});
    double t = 1e300;
    if (dir.x != 0) t = std::min(t, half_u / std::abs(dir.x));
    if (dir.y != 0) t = std::min(t, half_v / std::abs(dir.y));
    outward[k] = dir;
    m.at_px = centre_px + t * dir;
  }

  // Two pointers on top of each other: move the second along the edge.
  if (!marks[0].on_map && !marks[1].on_map) {
    const cv::Point2d gap = marks[1].at_px - marks[0].at_px;
    if (std::hypot(gap.x, gap.y) < 36) {
      const cv::Point2d along(-outward[1].y, outward[1].x);
      cv::Point2d moved = marks[0].at_px + 36 * along;
      if (std::abs(moved.x - centre_px.x) > half_u + 0.5 ||
          std::abs(moved.y - centre_px.y) > half_v + 0.5) {
        moved = marks[0].at_px - 36 * along;
      }
      marks[1].at_px = moved;
    }
  }

  // Labels point away from the other mark (s and c are often close), or inwards for pointers.
  for (size_t k = 0; k < marks.size(); ++k) {
    Mark& m = marks[k];
    if (!m.on_map) {
      m.label_dir = -outward[k];
      continue;
    }
    const cv::Point2d away = m.at_px - marks[1 - k].at_px;
    m.label_dir = std::hypot(away.x, away.y) > 0.5 ? unit(away) : cv::Point2d(k == 0 ? -1 : 1, 0);
  }

  // c under s, so that coinciding marks both stay visible.
  for (size_t k : {size_t{1}, size_t{0}}) {
    const Mark& m = marks[k];
    if (m.on_map) {
      if (m.name == "s") {
        draw_stagnation_symbol(img, m.at_px);
      } else {
        draw_projection_symbol(img, m.at_px);
      }
    } else {
      draw_pointer(img, m.at_px, outward[k], m.name == "s" ? kStagnationRed : kProjectionMagenta);
    }
  }
  for (const Mark& m : marks) draw_mark_label(img, frame, m);
}

// One line under the axes: each mark's symbol, meaning and coordinates (smaller type if too long).
void draw_legend(cv::Mat& img, const std::array<Mark, 2>& marks) {
  constexpr int kSymbolWidth_px = 18, kSymbolGap_px = 8, kItemGap_px = 36;
  constexpr double kSymbolSize = 0.75;
  std::array<std::string, 2> texts;
  for (size_t k = 0; k < marks.size(); ++k) {
    const Mark& m = marks[k];
    char coords[96];
    std::snprintf(coords, sizeof coords,
                  std::abs(m.p_W.x()) < 1e4 && std::abs(m.p_W.y()) < 1e4 ? "(%.2f, %.2f) m"
                                                                         : "(%.3g, %.3g) m",
                  m.p_W.x(), m.p_W.y());
    texts[k] = m.name + (m.name == "s" ? ": stagnation point " : ": projection point ") + coords +
               (m.on_map ? "" : ", off the map");
  }
  TextStyle style = kLegendStyle;
  auto width = [&] {
    int total = kItemGap_px;
    for (const std::string& t : texts) {
      total += kSymbolWidth_px + kSymbolGap_px + text_size(t, style).width;
    }
    return total;
  };
  while (width() > kFieldPngWidth_px - 20 && style.scale > 0.3) style.scale *= 0.9;

  // Centred on the picture.
  double x = std::max(4.0, 0.5 * kFieldPngWidth_px - 0.5 * width());
  for (size_t k = 0; k < marks.size(); ++k) {
    const cv::Point2d symbol(x + 0.5 * kSymbolWidth_px, kLegendMiddle_px);
    if (marks[k].name == "s") {
      draw_stagnation_symbol(img, symbol, kSymbolSize);
    } else {
      draw_projection_symbol(img, symbol, kSymbolSize);
    }
    x += kSymbolWidth_px + kSymbolGap_px;
    const cv::Rect box = draw_text(img, texts[k], cv::Point2d(x, kLegendMiddle_px), HAlign::kLeft,
                                   VAlign::kMiddle, style);
    x = box.x + box.width + kItemGap_px;
  }
}

}  // namespace

FieldPlotArea field_plot_area(const VectorFieldGrid& grid) {
  const std::string where = "field picture";
  check_axis(grid.x, "x", where);
  check_axis(grid.y, "y", where);
  const cv::Rect a = map_area_px(grid);
  return {a.x, a.y, a.width, a.height};
}

void write_field_png(const VectorFieldGrid& grid, const FieldMarks& marks,
                     const std::string& path) {
  // Reject what cannot be drawn before drawing anything.
  const std::string where = "field picture " + path;
  check_axis(grid.x, "x", where);
  check_axis(grid.y, "y", where);
  check_values(grid.vx, "vx", grid, where);
  check_values(grid.vy, "vy", grid, where);
  check_values(grid.speed, "speed", grid, where);
  check_marks(marks, where);

  // The frame and the colour scale: from min(0, slowest) to the fastest (or the caller's top).
  cv::Mat img(kFieldPngHeight_px, kFieldPngWidth_px, CV_8UC3, kWhite);
  const PlotFrame frame(map_area_px(grid), grid.x[0], grid.x[grid.x.size() - 1], grid.y[0],
                        grid.y[grid.y.size() - 1]);
  const double top = marks.speed_max_mps > 0 ? marks.speed_max_mps : grid.speed.maxCoeff();
  const ColourScale scale(std::min(0.0, grid.speed.minCoeff()), top, cv::COLORMAP_VIRIDIS);

  // Speed map, arrows, axes, then s and c on top.
  draw_scalar_map(img, frame, grid.x, grid.y, grid.speed, scale);
  {
    cv::Mat map = img(frame.area_px());
    const PlotFrame local(cv::Rect(0, 0, map.cols, map.rows), frame.x_min(), frame.x_max(),
                          frame.y_min(), frame.y_max());
    draw_arrows(map, local, grid);  // clipped to the map
  }
  draw_axes(img, frame, "x (m)", "y (m)");
  std::array<Mark, 2> points = {Mark{"s", marks.stagnation_W}, Mark{"c", marks.projection_W}};
  draw_marks(img, frame, points);

  // Colour bar beside the map, title and subtitle above, legend below.
  const cv::Rect& a = frame.area_px();
  draw_colour_bar(img, cv::Rect(kColourBarLeft_px, a.y, kColourBarWidth_px, a.height), scale,
                  "air speed (m/s)");
  TextStyle title_style = kTitleStyle;
  const std::string title = marks.title.empty() ? std::string("air field") : marks.title;
  while (text_size(title, title_style).width > kFieldPngWidth_px - 40 && title_style.scale > 0.4) {
    title_style.scale *= 0.9;
  }
  draw_text(img, title, cv::Point2d(0.5 * kFieldPngWidth_px, kTitleBaseline_px), HAlign::kCentre,
            VAlign::kBaseline, title_style);
  draw_text(img, "colour: air speed;  arrows: air direction, length proportional to speed",
            cv::Point2d(0.5 * kFieldPngWidth_px, kSubtitleBaseline_px), HAlign::kCentre,
            VAlign::kBaseline, kSubtitleStyle);
  draw_legend(img, points);

  write_png(img, path);
}

}  // namespace airtwin::plots
