#pragma once
// One call per frame: every tracer and cotton wad in a top-view frame, classified, with its pixel
// centre and its position on the floor through the calibrated camera (vision/calibrated_camera.h).
//
// The pipeline (docs/vision.md):
//  1. Blobs (vision/blob_detector.h): everything clearly brighter than the floor, except the
//     nozzle rig, which hangs above the floor's origin: a blob reaching into a small disc around
//     its foot is the rig, or an object merged with the rig's image, and is dropped.
//  2. Objects in each blob, as seeds:
//     - tracers from the circular Hough transform (vision/circle_detector.h) run on the blob's
//       neighbourhood: a circle whose bright disc holds no more than ~a tracer's area is a tracer
//       (a circle found inside a wad holds the wad's brightness around it, and is rejected);
//     - what the tracers leave is peeled by its distance transform: a point deeper than a tracer's
//       radius can be is a wad's core (cotton), a point as deep as a tracer's core is a tracer the
//       transform missed; each seed takes its object's disc away and the next peak is examined;
//     - a blob of tracers alone holds as many as its area says (overlapping discs, as blur makes
//       touching tracers, can leave one too thin a piece to peel): missing ones go to the
//       deepest points left;
//     - a blob of one seed is that object, centred on the blob's centroid (image moments);
//       touching objects (a blob of several seeds) are split by a few Lloyd iterations that give
//       each blob pixel to the nearest seed (distances scaled by the object's radius) and move the
//       seeds to the centroids of their pixels. Their detections are marked as merged.
//     Thin or small shapes (noise, the rig's edges) hold no seed and are nothing.
//  3. World positions: the pixel centre back-projected to the plane at the type's visible height
//     (the centroid of a tracer's bright cap is the projection of a point ~5 mm up, a wad's ~16 mm;
//     measured on the twin's renders, docs/vision.md), of which x, y is the object's floor
//     position.
// Sizes are given in metres and converted to pixels with the camera's local scale, so the same
// options serve another camera height or resolution.

#include <Eigen/Core>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vision/blob_detector.h"
#include "vision/calibrated_camera.h"
#include "vision/circle_detector.h"

namespace airtwin {

/// What the detector tells apart.
enum class ObjectKind { kTracer = 0, kCotton = 1 };

/// "tracer" or "cotton".
const char* object_kind_name(ObjectKind kind);

struct ObjectDetectorOptions {
  BlobDetectorOptions blobs;
  CircleDetectorOptions circles;
  /// Diameter of a tracer's bright cap as seen from above (m): 2.8 cm of the 3 cm hemisphere (its
  /// rim is too oblique to the light to pass the threshold).
  double tracer_visible_diameter_m = 0.028;
  /// Diameter of a wad's bright area (m), ~4.1 cm for the twin's 5 cm wads.
  double cotton_visible_diameter_m = 0.041;
  /// Heights (m above the floor) of the points whose projections are the measured centres.
  double tracer_height_m = 0.005;
  double cotton_height_m = 0.016;
  /// Floor disc (world frame, m) under the nozzle rig, which the camera sees end-on as bright
  /// parts within ~7 cm of its foot (the rod's end, the servo bracket). A blob reaching into the
  /// disc is the rig or merged with it, and is dropped; so the disc must meet every rig part
  /// (5 cm: ~19 px, the bracket's plates start ~12 px out) and needs to be no bigger, so that
  /// objects beside the rig stay visible. Radius 0 = no mask.
  Eigen::Vector2d rig_centre_W = Eigen::Vector2d::Zero();
  double rig_mask_radius_m = 0.05;
  /// Use the Hough transform to find tracers in blobs bigger than a single tracer.
  bool use_hough = true;

  /// Throws InputError naming the field when a value is out of range.
  void validate() const;
};

struct Detection {
  ObjectKind kind = ObjectKind::kTracer;
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();  ///< (u, v) in the frame (px)
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();        ///< floor position (m), world frame
  double area_px = 0.0;     ///< the object's pixels (its share of a merged blob)
  int blob = -1;            ///< index of its blob in ObjectDetector::blobs()
  int objects_in_blob = 1;  ///< > 1: split from a blob of touching objects
  bool at_border = false;   ///< its blob touches the image's edge (may be cut, centre biased)
};

/// Per-frame summary of what the detector saw.
struct DetectionStats {
  int blobs = 0;         ///< bright blobs found (rig included)
  int masked_blobs = 0;  ///< dropped: reaching under the rig
  int empty_blobs = 0;   ///< held no object (noise, thin edges)
  int merged_blobs = 0;  ///< held more than one object
  int unplaced = 0;      ///< objects whose pixel the camera could not take to the floor
};

/// Reusable detector (scratch images kept between frames). One per thread.
class ObjectDetector {
 public:
  /// Throws InputError for bad options or a camera without an image size.
  ObjectDetector(const CalibratedCamera& camera, const ObjectDetectorOptions& options = {});

  /// The objects of an 8-bit BGR or grey frame of the camera's size, sorted by v then u.
  /// Throws InputError for an empty frame, another pixel type or another size.
  const std::vector<Detection>& detect(const cv::Mat& frame);

  /// Of the last detect().
  const std::vector<Blob>& blobs() const { return blobs_; }
  const DetectionStats& stats() const { return stats_; }
  const CalibratedCamera& camera() const { return camera_; }
  const ObjectDetectorOptions& options() const { return options_; }
  /// The rig mask (CV_8UC1, non-zero = ignored), empty without one.
  const cv::Mat& rig_mask() const { return rig_mask_; }

 private:
  struct Seed {
    ObjectKind kind;
    Eigen::Vector2d centre_px;
  };
  // Sizes of the two kinds at a pixel (px): radii of the visible discs.
  struct LocalScale {
    double tracer_radius_px = 0.0, cotton_radius_px = 0.0;
  };
  LocalScale local_scale(const Eigen::Vector2d& uv_px) const;
  std::vector<Seed> seeds_of(const Blob& blob, const LocalScale& scale);
  void refine(const Blob& blob, const LocalScale& scale, std::vector<Seed>& seeds,
              std::vector<double>& areas) const;

  CalibratedCamera camera_;
  ObjectDetectorOptions options_;
  BlobDetector blob_detector_;
  cv::Mat rig_mask_;
  std::vector<Blob> blobs_;
  std::vector<Detection> detections_;
  DetectionStats stats_;
  cv::Mat remaining_, blob_depth_, distance_;
};

/// One-shot form of ObjectDetector::detect.
std::vector<Detection> detect_objects(const cv::Mat& frame, const CalibratedCamera& camera,
                                      const ObjectDetectorOptions& options = {});

}  // namespace airtwin
