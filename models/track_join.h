#pragma once
// From a camera's tracks to trajectories: the detections CSV that `airtwin detect` writes (one row
// per detection, `frame,t,id,object,x,y[,x_px,y_px]`, docs/data_formats.md) joined by time with
// the nozzle's command log (models/nozzle_log.h) into the trajectory CSV that identification and
// the discrepancy analysis read (models/trajectory_data.h). `airtwin trajectories`.
//
// A track is the rows of one id. vision/'s tracker numbers tracks 1, 2, ... and never gives an
// id twice; a track ends when it has had no detection for more than max_missed_frames frames
// (lost, merges included) or at once at the image's edge. So an id whose rows resume after a gap
// of more than max_missed_frames frames is a reused id: another object under an old number, which
// vision/ never writes, and an error here. Gaps up to that length are missed frames: the track is
// cut there into pieces of consecutive frames (identification needs every frame of a trajectory).
//
// Each row takes the command in force at its time (the last command at or before it). Tracks of
// other types than the one asked for, tracks with a step faster than a physical bound (a wrong
// association, not motion) and tracks or pieces shorter than a minimum are dropped and counted,
// never silently. Optionally the pieces are cut further at every command change: the Appendix D
// trials (one command each); otherwise a piece keeps every command it lived through (closed-loop
// segments, one command per row).

#include <Eigen/Core>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "models/nozzle_log.h"
#include "models/trajectory_data.h"

namespace airtwin {

/// One detection: a row of the detections CSV.
struct DetectionRow {
  int64_t frame = 0;  ///< 0-based frame index
  double t_s = 0.0;   ///< the frame's time (s)
  std::string track;  ///< the track's id (text)
  std::string object;
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();  ///< floor position (m, world frame)
  size_t line = 0;                                ///< 1-based line in the file
};

/// A validated detections file, rows in file order.
struct DetectionTable {
  std::string source;
  std::vector<DetectionRow> rows;
};

/// Reads and validates a detections CSV (`detect --out`, or a render's truth.csv, which has the
/// same columns): columns frame, t, id, object, x, y (x_px, y_px optional, finite when present);
/// frame a whole number >= 0, never decreasing from row to row; one time per frame, increasing
/// from frame to frame; a non-empty id, at most once per frame; a known object type; at least one
/// row. Throws InputError naming the file, the line, the column and the value.
DetectionTable read_detections_csv(
    const std::string& path, const std::set<std::string>& known_objects = default_object_types());
/// Same, from text in memory; `source` names it in messages.
DetectionTable parse_detections_csv(
    const std::string& text, const std::string& source,
    const std::set<std::string>& known_objects = default_object_types());

struct TrackJoinOptions {
  /// Cut at every command change (Appendix D trials: one command per trajectory); false: keep
  /// the commands a track lived through, one per row (closed-loop segments).
  bool cut_trials = false;
  /// Fewer rows than this: the track (or the piece) is dropped. >= 2.
  int min_frames = 10;
  /// A step between consecutive rows of a track faster than this (m/s) drops the track: twice
  /// the fastest object the jet blows (1.3 m/s) and 1.5 times vision/'s gate (5 cm a frame at
  /// 40 Hz).
  double max_speed_mps = 3.0;
  /// The tracker's max_missed_frames: a longer gap in a track's frames means a reused id. >= 0.
  int max_missed_frames = 8;
  /// Keep only this object type; empty: every type.
  std::string object;
  /// How far the nozzle log's clock runs behind the camera's (s): a command logged at t acted at
  /// t + clock_offset_s on the detections' clock. Two machines' clocks, or a servo log started
  /// at its own zero. The written times are the camera's. |offset| <= 1 day.
  double clock_offset_s = 0.0;

  /// Throws FieldError naming the field (`track_join.min_frames`, `track_join.max_speed_mps`,
  /// `track_join.max_missed_frames`, `track_join.object`, `track_join.clock_offset_s`) for a
  /// value out of range or an unknown object type.
  void validate(const std::set<std::string>& known_objects = default_object_types()) const;
};

/// A track dropped as too short or for a jump, for the report.
struct DroppedTrack {
  std::string track;
  size_t rows = 0;
  int64_t frame = 0;       ///< jump: the frame it jumped to
  double speed_mps = 0.0;  ///< jump: the step's speed
};

struct TrackJoinReport {
  size_t rows = 0;             ///< detections read
  size_t tracks = 0;           ///< ids in the file
  size_t commands = 0;         ///< rows of the nozzle log
  size_t command_changes = 0;  ///< of which change the command (the first counts as one)
  size_t other_object_tracks = 0, other_object_rows = 0;  ///< not of options.object
  std::vector<DroppedTrack> jumps;                ///< dropped: a step faster than max_speed_mps
  std::vector<DroppedTrack> short_tracks;         ///< dropped: fewer than min_frames rows
  size_t gaps = 0;                                ///< missed-frame gaps the kept tracks were cut at
  size_t trial_cuts = 0;                          ///< command changes the kept tracks were cut at
  size_t short_pieces = 0, short_piece_rows = 0;  ///< pieces dropped: fewer than min_frames rows
  size_t trajectories = 0, samples = 0;           ///< written
};

struct TrackJoinResult {
  TrajectorySet set;
  TrackJoinReport report;
};

/// Joins the tracks of `detections` with the commands of `nozzle` (see above), the log's times
/// shifted by options.clock_offset_s. Trajectories in
/// the order of their tracks' first rows, then in time; a trajectory's id is its track's id, or
/// `<id>.<k>` for the k-th piece (1-based, in time) of a track cut into several (dropped pieces
/// count). Throws FieldError for bad options; InputError naming the file and line when the log
/// starts after the first detection (it does not cover the recording), when an id is reused (see
/// above), or when nothing is left to write (the message gives the counts).
TrackJoinResult join_tracks(const DetectionTable& detections, const NozzleLog& nozzle,
                            const TrackJoinOptions& options);

}  // namespace airtwin
