#pragma once
// Tracer detection in a top-view frame by circle detection, as the paper's controller does
// (section V: "objects are detected using top-view image processing, through the circle detection
// algorithm"), here the circular Hough transform: grey conversion, a 9 x 9 Gaussian blur,
// OpenCV's HOUGH_GRADIENT with radii bounded around the expected tracer radius, then a sub-pixel
// refinement of each centre by the intensity-weighted centroid of the bright pixels within the
// found radius (the Hough accumulator alone is good to ~1-3 px).
// Defaults for the rig's camera (1024 px over ~2.7 m, 2.64 mm/px): a 3 cm tracer's bright cap has
// a Hough radius of ~4.6 px; a 5 cm cotton wad's ~7.3 px, kept out by max_radius_px.
//
// The detector works in pixels and knows nothing of the world or of how the frame was made: it is
// the code that reads the rig's camera. Pixel convention: (u, v) = (column, row) of pixel
// centres, u right, v down, as OpenCV.

#include <Eigen/Core>
#include <vector>

#include <opencv2/core.hpp>

namespace airtwin {

struct CircleDetectorOptions {
  double min_radius_px = 3.0;           ///< smallest tracer radius in the image
  double max_radius_px = 6.0;           ///< largest
  double min_distance_px = 8.0;         ///< between two centres (touching 3 cm tracers: ~11 px)
  double edge_threshold = 100.0;        ///< Canny's upper threshold (HOUGH_GRADIENT param1)
  double accumulator_threshold = 12.0;  ///< votes a centre needs (param2); lower finds more
  int bright_threshold = 170;           ///< grey level above which a pixel belongs to a tracer

  /// Throws InputError naming the field when a value is not finite or out of order.
  void validate() const;
};

struct DetectedCircle {
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();  ///< refined centre (u, v)
  double radius_px = 0.0;                               ///< Hough radius
  int bright_pixels = 0;  ///< pixels above the bright threshold within the radius
};

/// The circles in an 8-bit BGR or grey frame, sorted by v then u. Throws InputError for an empty
/// image or another pixel type.
std::vector<DetectedCircle> detect_circles(const cv::Mat& frame,
                                           const CircleDetectorOptions& options = {});

}  // namespace airtwin
