#pragma once
// Bright objects on the floor as blobs: every connected region of pixels clearly brighter than the
// floor, with the area and shape features the classifier (vision/object_detector.h) needs and a
// centre from image moments. Tracers and cotton wads alike are white on a grey floor, so one pass
// finds both; telling them apart is the object detector's job.
//
// Per frame: grey conversion; the floor's level, the median grey of a sparse grid of pixels (the
// objects cover a few per cent of the view); a threshold `threshold_above_floor` grey levels
// above it (never below `min_threshold`); a morphological opening that removes specks of sensor
// noise; the outer contours of what is left, each one blob (8-connected; a hole inside a blob is
// not part of it). Per blob: its pixel mask, pixel area, perimeter of the contour, circularity
// 4 pi A / P^2 (~1 for a disc), elongation sqrt(l1 / l2) of the second moments, depth (the largest
// distance from a blob pixel to the background), and the centroid of its pixels weighted by their
// brightness above the floor (a half-covered edge pixel counts less; saturated pixels count
// fully). Contours rather than a labelling of the whole image: the objects cover ~1 % of it, and
// OpenCV's labelling with statistics costs ~10 ms a frame on its own.
//
// Pixel convention: (u, v) = (column, row) of pixel centres, u right, v down, as OpenCV. The
// detector knows nothing of the world or of how the frame was made.

#include <Eigen/Core>
#include <vector>

#include <opencv2/core.hpp>

namespace airtwin {

struct BlobDetectorOptions {
  /// Grey levels above the floor's median level from which a pixel belongs to an object. The
  /// twin's floor is ~80-90, its white objects saturate at 255: 75 keeps > 10 sigma of sensor
  /// noise (6 grey levels) away on both sides.
  int threshold_above_floor = 75;
  /// The threshold never goes below this (a frame full of white would otherwise lower it).
  int min_threshold = 100;
  /// Side of the square structuring element of the opening (px); 1 = no opening.
  int opening_px = 3;
  /// Components smaller than this are noise (px).
  double min_area_px = 12.0;

  /// Throws InputError naming the field when a value is out of range.
  void validate() const;
};

struct Blob {
  Eigen::Vector2d centroid_px = Eigen::Vector2d::Zero();  ///< brightness-weighted centre (u, v)
  double area_px = 0.0;                                   ///< pixels above the threshold
  double perimeter_px = 0.0;                              ///< length of the outer contour
  double circularity = 0.0;       ///< 4 pi area / perimeter^2 (~1 for a disc, less when lobed)
  double elongation = 1.0;        ///< sqrt of the ratio of the second moments' eigenvalues (>= 1)
  double peak_distance_px = 0.0;  ///< largest distance from a blob pixel to the background
  cv::Rect box;                   ///< bounding box (px)
  cv::Mat mask;                   ///< CV_8UC1 of box's size: 255 on the blob's pixels, else 0
  bool touches_border = false;    ///< reaches the image's edge: the object may be cut
  bool touches_mask = false;      ///< has pixels in the ignore mask (e.g. under the nozzle rig)
};

/// Reusable detector: keeps its scratch images between frames (no allocation per frame once the
/// size is steady). One per thread.
class BlobDetector {
 public:
  /// Throws InputError for bad options.
  explicit BlobDetector(const BlobDetectorOptions& options = {});

  /// The blobs of an 8-bit BGR or grey frame, sorted by v then u. `ignore_mask` (optional,
  /// CV_8UC1 of the frame's size): its non-zero pixels never belong to a blob, and a blob that
  /// reaches into them is returned with touches_mask set. Throws InputError for an empty frame,
  /// another pixel type, or a mask of another size or type.
  const std::vector<Blob>& detect(const cv::Mat& frame, const cv::Mat& ignore_mask = cv::Mat());

  /// Of the last detect(): the grey image, the floor's grey level and the threshold used.
  const cv::Mat& grey() const { return grey_; }
  double floor_grey() const { return floor_grey_; }
  int threshold_grey() const { return threshold_; }
  const BlobDetectorOptions& options() const { return options_; }

 private:
  BlobDetectorOptions options_;
  cv::Mat grey_, binary_, opened_, kernel_, padded_, distance_;
  std::vector<std::vector<cv::Point>> contours_;
  std::vector<Blob> blobs_;
  double floor_grey_ = 0.0;
  int threshold_ = 0;
};

/// One-shot form of BlobDetector::detect.
std::vector<Blob> detect_blobs(const cv::Mat& frame, const BlobDetectorOptions& options = {});

/// The floor's grey level of a grey frame: the median of every 4th pixel of every 4th row.
double floor_grey_level(const cv::Mat& grey);

}  // namespace airtwin
