#pragma once
// Object identities across frames: each frame's detections (vision/object_detector.h) are
// assigned to the live tracks by a minimum-cost assignment (Hungarian algorithm) on the distances
// between the detections and the tracks' constant-velocity predictions, within a gate; what is
// left over starts new tracks. A track that gets no detection coasts on its prediction for up to
// `max_missed_frames` frames (two touching objects seen as one, a detection dropped under noise)
// and is ended after that as lost; a track missed near the image's edge is ended at once as gone
// out of view.
//
// Per track: the velocity (m/s) is the derivative at the last detection of a least-squares
// parabola (or line) in time through its last detections (up to `velocity_window` of them), the
// input the controller needs; its kind is the majority of
// its detections' kinds (ties: the first seen). World frame and SI units throughout: positions in
// m, times in s.
//
// Gating: a detection may join a track only within max_jump_m of its predicted position for each
// frame since the track was last seen (an object cannot travel farther per camera period); two
// different kinds cost `kind_mismatch_m` more. Leaving a track or a detection unassigned costs
// more than any pair within a gate, so the assignment pairs all it can and, among those pairings,
// minimises the sum of distances: a detection goes to the track that predicted it best, whether
// that track was seen in the last frame or has been coasting.
//
// Merges: when a track gets no detection while its prediction lies within merge_radius_m of a
// detection another track took, the two objects are taken to be one blob (touching objects the
// detector could not split). The blob's centre is neither object's, so both tracks go on with
// their predictions and velocities unchanged until the objects are seen apart again; the
// detection keeps the other track's id. Deterministic: same inputs, same ids.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "vision/object_detector.h"

namespace airtwin {

struct TrackerOptions {
  /// Farthest an object moves in one frame (m): 5 cm = 2 m/s at 40 Hz.
  double max_jump_m = 0.05;
  /// Frames a track coasts without a detection before it is ended as lost.
  int max_missed_frames = 8;
  /// Detections in the velocity fit (>= 2).
  int velocity_window = 5;
  /// Degree of the polynomial fitted to them: 2 (a parabola: the velocity at the last frame,
  /// right under acceleration) or 1 (a line: the mean velocity over the window, less noisy, but
  /// half a window late when the object accelerates).
  int velocity_degree = 2;
  /// Extra cost of giving a detection of the other kind to a track (m).
  double kind_mismatch_m = 0.02;
  /// A track missed while its predicted pixel is within this of the image's edge has left the
  /// view and is ended (px). Needs the image size; 0 x 0 = unknown (tracks are only lost).
  double border_margin_px = 12.0;
  int image_width_px = 0;
  int image_height_px = 0;
  /// A missed track whose prediction lies within this of another track's detection (m) counts as
  /// merged with it (hidden in one blob) rather than simply missed.
  double merge_radius_m = 0.045;

  /// Throws InputError naming the field when a value is out of range.
  void validate() const;
};

struct Track {
  int id = 0;                             ///< 1, 2, ... in order of creation
  ObjectKind kind = ObjectKind::kTracer;  ///< majority of its detections
  /// Position (m): the last detection's; in a merge (another track holds the detection of the
  /// blob it is hidden in), the prediction.
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();
  Eigen::Vector2d v_W = Eigen::Vector2d::Zero();        ///< velocity estimate (m/s)
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();  ///< last detected pixel centre
  Eigen::Vector2d v_px = Eigen::Vector2d::Zero();       ///< pixel velocity (px/s), same fit
  double t_last_s = 0.0;                                ///< time of the last detection (s)
  double t_first_s = 0.0;                               ///< time of the first detection (s)
  int hits = 0;                                         ///< frames with a detection
  int missed_frames = 0;  ///< consecutive frames without one (0: detected in the last frame)
  int detection = -1;     ///< index of its detection in the last update, -1 when missed
  std::array<int, 2> kind_votes{0, 0};  ///< detections per kind (tracer, cotton)

  /// Position predicted at time t_s (m): constant velocity from the last detection.
  Eigen::Vector2d predict(double t_s) const { return p_W + v_W * (t_s - t_last_s); }
};

/// Totals over the updates so far.
struct TrackerCounters {
  int64_t frames = 0;
  int64_t detections = 0;
  int64_t new_tracks = 0;    ///< tracks started
  int64_t missed = 0;        ///< track-frames without a detection (merged ones included)
  int64_t merged = 0;        ///< of those, the track was beside another track's detection
  int64_t lost = 0;          ///< tracks ended after max_missed_frames
  int64_t left_view = 0;     ///< tracks ended at the image's edge
  int64_t entered_view = 0;  ///< tracks started at the image's edge after the first frame
};

class Tracker {
 public:
  /// Throws InputError for bad options.
  explicit Tracker(const TrackerOptions& options = {});

  /// Takes the detections of the frame at time t_s (s, after the previous update's). Returns the
  /// live tracks after it, in id order: those detected now (Track::detection set) and those
  /// coasting. Throws InputError when t_s is not finite or not after the previous time.
  const std::vector<Track>& update(double t_s, const std::vector<Detection>& detections);

  /// Of the last update: for each detection, the id of the track it went to.
  const std::vector<int>& detection_ids() const { return detection_ids_; }
  /// Tracks ended by the last update (lost or out of view), as they were when last alive.
  const std::vector<Track>& ended() const { return ended_; }
  const std::vector<Track>& tracks() const { return tracks_; }
  const TrackerCounters& counters() const { return counters_; }
  const TrackerOptions& options() const { return options_; }

 private:
  struct History {
    std::deque<double> t;
    std::deque<Eigen::Vector2d> p, uv;
  };
  void record(Track& track, History& history, const Detection& d, double t_s, int index);
  bool near_edge(const Eigen::Vector2d& uv_px) const;

  TrackerOptions options_;
  std::vector<Track> tracks_;
  std::vector<History> histories_;  // parallel to tracks_
  std::vector<Track> ended_;
  std::vector<int> detection_ids_;
  TrackerCounters counters_;
  int next_id_ = 1;
  bool started_ = false;
  double last_t_s_ = 0.0;
};

/// The header of the detections CSV (docs/data_formats.md, "Detections"; `detect --out`).
inline constexpr const char* kDetectionsCsvHeader = "frame,t,id,object,x,y,x_px,y_px\n";

/// The detections CSV's rows of one frame: `detections` as `tracker`'s last update took them at
/// time t_s (s), `frame` the frame's 0-based index in its input. One row per detection, in id
/// order; `object` the track's kind by vote; six decimals in every number but frame and id.
std::string detection_rows_csv(const Tracker& tracker, const std::vector<Detection>& detections,
                               int64_t frame, double t_s);

/// Minimum-cost assignment of rows to columns of a rectangular cost matrix (Hungarian algorithm,
/// O(n^3)). Returns for each row its column, or -1 when the matrix has more rows than columns and
/// the row is left out. Costs must be finite.
std::vector<int> solve_assignment(const Eigen::MatrixXd& cost);

}  // namespace airtwin
