#pragma once
// The canvas every picture for people is drawn on: a plot frame that maps a data rectangle onto a
// pixel rectangle (data y up, image rows down), "nice" axis ticks, and the furniture plots share
// (axes with ticks and labels, a colour scale with its colour bar, a scalar map, text with an
// optional halo, text rotated to read upwards). OpenCV, BGR 8-bit images, anti-aliased drawing,
// deterministic: the same calls give the same pixels.
//
// Pixel coordinates are OpenCV's: (u, v) = (column, row), integer values at pixel centres.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace airtwin::plots {

// ---- Colours (BGR) ------------------------------------------------------------------------------

inline const cv::Scalar kBlack(0, 0, 0);
inline const cv::Scalar kWhite(255, 255, 255);
inline const cv::Scalar kDarkGrey(60, 60, 60);

// ---- Plot frame ---------------------------------------------------------------------------------

/// A linear map from the data rectangle [x_min, x_max] x [y_min, y_max] onto the pixel centres of
/// area_px: x_min -> column area_px.x, x_max -> column area_px.x + width - 1, y_max -> row
/// area_px.y (top), y_min -> the bottom row (y up). Data units are the caller's (m for maps).
class PlotFrame {
 public:
  /// Requires x_min < x_max, y_min < y_max (finite) and an area at least 2 x 2 px; a violation is
  /// a bug in the caller and aborts (AIRTWIN_DEMAND).
  PlotFrame(cv::Rect area_px, double x_min, double x_max, double y_min, double y_max);

  const cv::Rect& area_px() const { return area_px_; }
  double x_min() const { return x_min_; }
  double x_max() const { return x_max_; }
  double y_min() const { return y_min_; }
  double y_max() const { return y_max_; }
  /// Pixels per data unit along x and along y (both > 0; rows grow as y falls).
  double px_per_x() const { return px_per_x_; }
  double px_per_y() const { return px_per_y_; }

  /// Pixel column (u) and row (v) of the data point (x, y); outside the area for points outside
  /// the data rectangle. Not clamped.
  cv::Point2d to_px(double x, double y) const;
  cv::Point2d to_px(const Eigen::Vector2d& p) const { return to_px(p.x(), p.y()); }
  /// Data x at pixel column u and data y at pixel row v (inverse of to_px).
  double x_at_column(double u) const;
  double y_at_row(double v) const;
  /// True when (x, y) lies in the closed data rectangle.
  bool contains(const Eigen::Vector2d& p) const;

 private:
  cv::Rect area_px_;
  double x_min_, x_max_, y_min_, y_max_;
  double px_per_x_, px_per_y_;
};

// ---- Ticks --------------------------------------------------------------------------------------

/// Tick values of an axis and the number of decimals that prints them without noise.
struct Ticks {
  std::vector<double> values;  ///< ascending, inside [lo, hi]
  double step = 0.0;           ///< spacing of the values
};

/// About target_count "nice" ticks (steps 1, 2 or 5 x 10^k) inside [lo, hi]. Requires finite
/// lo < hi. When no nice step fits (ranges far below the resolution of double), returns lo and hi.
Ticks nice_ticks(double lo, double hi, int target_count);

/// A tick label for value v on an axis with tick spacing `step`: fixed point with just enough
/// decimals ("0.5", "-1.0", "12"), "%g" style for very large or very small values; never "-0".
std::string format_tick(double v, double step);

// ---- Text ---------------------------------------------------------------------------------------

enum class HAlign { kLeft, kCentre, kRight };
enum class VAlign { kTop, kMiddle, kBaseline };

/// Hershey simplex text. halo_px > 0 draws an outline of that width in halo_colour first, which
/// keeps text readable on top of a colour map.
struct TextStyle {
  double scale = 0.55;
  int thickness = 1;
  cv::Scalar colour = kBlack;
  int halo_px = 0;
  cv::Scalar halo_colour = kWhite;
};

/// Width and cap height (px) of `text` in `style`, without the descent below the baseline.
cv::Size text_size(const std::string& text, const TextStyle& style);

/// Draws `text` aligned at `anchor` (px); returns the pixel box it occupies (halo included).
/// Parts outside the image are clipped.
cv::Rect draw_text(cv::Mat& img, const std::string& text, cv::Point2d anchor, HAlign h, VAlign v,
                   const TextStyle& style);

/// Draws `text` rotated by 90 degrees to read from bottom to top, centred at `centre` (px). Dark
/// text on a light background only (the text darkens what is underneath; no halo).
void draw_text_upwards(cv::Mat& img, const std::string& text, cv::Point2d centre,
                       const TextStyle& style);

// ---- Axes ---------------------------------------------------------------------------------------

/// Draws a 1 px frame just outside frame.area_px(), outward ticks with labels below (x) and left
/// (y) of it, and the axis labels (the y label rotated). Tick labels use format_tick.
void draw_axes(cv::Mat& img, const PlotFrame& frame, const std::string& x_label,
               const std::string& y_label);

/// The frame and the y half of draw_axes (y ticks, labels, the rotated y label), for plots whose x
/// axis is not numeric (categories the caller labels).
void draw_y_axis(cv::Mat& img, const PlotFrame& frame, const std::string& y_label);

// ---- Colour scale -------------------------------------------------------------------------------

/// Values in [lo, hi] -> the 256 colours of an OpenCV colour map; values outside saturate.
class ColourScale {
 public:
  /// A degenerate range (hi <= lo, e.g. a constant field) becomes [lo, lo + 1] or, when lo is
  /// large, [lo, lo + |lo|], so a colour bar can still be drawn. lo and hi must be finite (else
  /// AIRTWIN_DEMAND aborts).
  ColourScale(double lo, double hi, int colormap);

  double lo() const { return lo_; }
  double hi() const { return hi_; }
  int colormap() const { return colormap_; }
  /// Index 0..255 of value v into the colour map: round(255 (v - lo) / (hi - lo)), clamped.
  /// NaN gives 0.
  unsigned char index(double v) const;
  /// BGR colour of value v.
  cv::Vec3b colour(double v) const;

 private:
  double lo_, hi_;
  int colormap_;
  cv::Mat lut_;  // 256 x 1 BGR, the colour map's table
};

/// Draws a vertical colour bar (lo at the bottom) filling bar_px, framed, with ticks and labels on
/// its right and `label` rotated beside them.
void draw_colour_bar(cv::Mat& img, cv::Rect bar_px, const ColourScale& scale,
                     const std::string& label);

// ---- Sampling a rectilinear grid ----------------------------------------------------------------

/// Where coordinate q falls on ascending nodes: between nodes i and i + 1 at fraction t in [0, 1]
/// (q outside the nodes is clamped to the end cell).
struct GridCell {
  Eigen::Index i = 0;
  double t = 0.0;
};
GridCell locate(const Eigen::VectorXd& nodes, double q);

/// Bilinear interpolation of values (rows = y index, columns = x index) at cells cx (x) and cy (y).
double bilinear(const Eigen::MatrixXd& values, const GridCell& cx, const GridCell& cy);

/// Fills frame.area_px() with the colours of `values` (ny x nx, rows = y index) sampled on the
/// ascending nodes x (nx) and y (ny), bilinearly interpolated at each pixel centre.
void draw_scalar_map(cv::Mat& img, const PlotFrame& frame, const Eigen::VectorXd& x,
                     const Eigen::VectorXd& y, const Eigen::MatrixXd& values,
                     const ColourScale& scale);

// ---- Output ------------------------------------------------------------------------------------

/// Writes `img` as a PNG file; throws InputError naming the path when encoding or writing fails.
void write_png(const cv::Mat& img, const std::string& path);

}  // namespace airtwin::plots
