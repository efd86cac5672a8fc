// Tracks joined with the nozzle's command log: each row's command against a scan of the log, cuts
// at missed frames and at command changes, what is dropped and counted, and one clear error for
// every bad input (unsorted or repeated times, a reused id, a log that starts too late, NaN).

#include "models/track_join.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {
namespace {

constexpr double kDt = 0.025;  // 40 Hz
const std::string kHeader = "frame,t,id,object,x,y,x_px,y_px\n";

// One detection row as detect writes it.
std::string row(int frame, const std::string& id, const std::string& object, double x, double y) {
  char text[160];
  std::snprintf(text, sizeof text, "%d,%.6f,%s,%s,%.6f,%.6f,512.0,512.0\n", frame, frame * kDt,
                id.c_str(), object.c_str(), x, y);
  return text;
}

// Frames [first, last] of an object moving at (vx, vy) m/s from (x0, y0), skipping `missing`.
std::map<int, std::string> track_rows(const std::string& id, const std::string& object, int first,
                                      int last, double x0, double y0, double vx, double vy,
                                      std::vector<int> missing = {}) {
  std::map<int, std::string> out;
  for (int f = first; f <= last; ++f) {
    if (std::find(missing.begin(), missing.end(), f) != missing.end()) continue;
    out[f] = row(f, id, object, x0 + vx * (f - first) * kDt, y0 + vy * (f - first) * kDt);
  }
  return out;
}

// The rows of several tracks, frame by frame.
std::string detections(const std::vector<std::map<int, std::string>>& tracks) {
  std::map<int, std::string> by_frame;
  for (const auto& t : tracks) {
    for (const auto& [f, r] : t) by_frame[f] += r;
  }
  std::string out = kHeader;
  for (const auto& [f, r] : by_frame) out += r;
  return out;
}

const char* kLog =
    "t,pan_deg,tilt_deg\n"
    "0,30,10\n"
    "0.5,30,10\n"   // a servo sample repeating the command: no change
    "0.75,60,20\n"  // frame 30 exactly: in force from it
    "1.5,90,40\n";

TrackJoinResult join(const std::string& det, const std::string& log, TrackJoinOptions o = {}) {
  return join_tracks(parse_detections_csv(det, "d.csv"), parse_nozzle_log(log, "n.csv"), o);
}

std::string error_of(const std::string& det, const std::string& log, TrackJoinOptions o = {}) {
  try {
    join(det, log, o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The command in force at t by a scan of the log's rows (degrees), independent of index_at.
std::pair<double, double> command_by_scan(double t) {
  const double times[] = {0, 0.5, 0.75, 1.5}, pans[] = {30, 30, 60, 90}, tilts[] = {10, 10, 20, 40};
  int in_force = -1;
  for (int i = 0; i < 4; ++i) {
    if (times[i] <= t + 1e-12) in_force = i;
  }
  return {pans[in_force], tilts[in_force]};
}

TEST(TrackJoin, EachRowTakesTheCommandInForceAtItsFrame) {
  const std::string det = detections({track_rows("1", "tracer", 0, 79, 0.2, 0.1, 0.3, 0.0),
                                      track_rows("2", "cotton", 5, 70, -0.3, 0.4, 0.0, -0.2)});
  const TrackJoinResult r = join(det, kLog);
  ASSERT_EQ(r.set.trajectories.size(), 2u);
  EXPECT_EQ(r.report.rows, 80u + 66u);
  EXPECT_EQ(r.report.tracks, 2u);
  EXPECT_EQ(r.report.commands, 4u);
  EXPECT_EQ(r.report.command_changes, 3u);
  EXPECT_EQ(r.report.trajectories, 2u);
  EXPECT_EQ(r.report.samples, 146u);
  const Trajectory& a = r.set.trajectories[0];
  EXPECT_EQ(a.id, "1");
  EXPECT_EQ(a.object, "tracer");
  ASSERT_EQ(a.samples.size(), 80u);
  for (size_t k = 0; k < a.samples.size(); ++k) {
    const auto [pan, tilt] = command_by_scan(a.samples[k].t_s);
    EXPECT_NEAR(rad_to_deg(a.samples[k].nozzle.pan_rad), pan, 1e-12) << k;
    EXPECT_NEAR(rad_to_deg(a.samples[k].nozzle.tilt_rad), tilt, 1e-12) << k;
    EXPECT_NEAR(a.samples[k].p_W.x(), 0.2 + 0.3 * k * kDt, 1e-6);
  }
  EXPECT_NEAR(rad_to_deg(a.samples[29].nozzle.pan_rad), 30, 1e-12);
  EXPECT_NEAR(rad_to_deg(a.samples[30].nozzle.pan_rad), 60, 1e-12);  // t = 0.75 exactly
  EXPECT_EQ(r.set.trajectories[1].id, "2");
  EXPECT_EQ(r.set.trajectories[1].object, "cotton");
  EXPECT_EQ(r.set.trajectories[1].samples.front().t_s, 5 * kDt);
  // What it returns is a trajectory CSV that reads back.
  EXPECT_EQ(parse_trajectory_csv(trajectory_csv(r.set), "out.csv").trajectories.size(), 2u);
}

TEST(TrackJoin, TrialsAreCutAtCommandChangesOnly) {
  const std::string det = detections({track_rows("1", "tracer", 0, 79, 0.2, 0.1, 0.3, 0.0),
                                      track_rows("2", "tracer", 35, 55, -0.3, 0.4, 0.0, -0.2)});
  TrackJoinOptions o;
  o.cut_trials = true;
  const TrackJoinResult r = join(det, kLog, o);
  // Track 1: frames 0-29 (30, 10), 30-59 (60, 20), 60-79 (90, 40); the repeated command at 0.5 s
  // is no cut. Track 2 lies in one period: one trajectory, its own id.
  ASSERT_EQ(r.set.trajectories.size(), 4u);
  EXPECT_EQ(r.report.trial_cuts, 2u);
  const std::vector<std::pair<std::string, size_t>> expected = {
      {"1.1", 30}, {"1.2", 30}, {"1.3", 20}, {"2", 21}};
  for (size_t i = 0; i < expected.size(); ++i) {
    const Trajectory& t = r.set.trajectories[i];
    EXPECT_EQ(t.id, expected[i].first);
    ASSERT_EQ(t.samples.size(), expected[i].second) << t.id;
    // One command per trial.
    for (const TrajectorySample& s : t.samples) {
      EXPECT_EQ(s.nozzle.pan_rad, t.samples.front().nozzle.pan_rad) << t.id;
      EXPECT_EQ(s.nozzle.tilt_rad, t.samples.front().nozzle.tilt_rad) << t.id;
    }
  }
  EXPECT_NEAR(r.set.trajectories[1].samples.front().t_s, 0.75, 1e-12);
  EXPECT_NEAR(rad_to_deg(r.set.trajectories[2].samples.front().nozzle.tilt_rad), 40, 1e-12);
}

TEST(TrackJoin, MissedFramesCutTheTrackAndShortPiecesAreCounted) {
  // Track 1 misses frames 20-22 (3, within the tracker's 8) and 75; the piece 76-79 is too short.
  const std::string det =
      detections({track_rows("1", "tracer", 0, 79, 0.2, 0.1, 0.3, 0.0, {20, 21, 22, 75})});
  const TrackJoinResult r = join(det, kLog);
  EXPECT_EQ(r.report.gaps, 2u);
  EXPECT_EQ(r.report.short_pieces, 1u);
  EXPECT_EQ(r.report.short_piece_rows, 4u);
  ASSERT_EQ(r.set.trajectories.size(), 2u);
  EXPECT_EQ(r.set.trajectories[0].id, "1.1");
  EXPECT_EQ(r.set.trajectories[0].samples.size(), 20u);
  EXPECT_EQ(r.set.trajectories[1].id, "1.2");
  EXPECT_EQ(r.set.trajectories[1].samples.size(), 52u);
  EXPECT_NEAR(r.set.trajectories[1].samples.front().t_s, 23 * kDt, 1e-12);
}

TEST(TrackJoin, JumpsShortTracksAndOtherTypesAreDroppedAndCounted) {
  // Track 2 steps 10 cm in one frame at frame 40 (4 m/s); track 3 has 9 frames; 4 is cotton.
  std::map<int, std::string> jumper = track_rows("2", "tracer", 0, 60, -0.3, 0.4, 0.5, 0.0);
  jumper[40] = row(40, "2", "tracer", -0.3 + 0.5 * 40 * kDt + 0.1, 0.4);
  const std::string det = detections({track_rows("1", "tracer", 0, 79, 0.2, 0.1, 0.3, 0.0), jumper,
                                      track_rows("3", "tracer", 10, 18, 0.5, 0.5, 0.1, 0.1),
                                      track_rows("4", "cotton", 0, 79, -0.5, -0.5, 0.1, 0.0)});
  TrackJoinOptions o;
  o.object = "tracer";
  const TrackJoinResult r = join(det, kLog, o);
  EXPECT_EQ(r.report.tracks, 4u);
  EXPECT_EQ(r.report.other_object_tracks, 1u);
  EXPECT_EQ(r.report.other_object_rows, 80u);
  ASSERT_EQ(r.report.jumps.size(), 1u);
  EXPECT_EQ(r.report.jumps[0].track, "2");
  EXPECT_EQ(r.report.jumps[0].frame, 40);
  EXPECT_NEAR(r.report.jumps[0].speed_mps, std::hypot(0.5 * kDt + 0.1, 0.0) / kDt, 1e-3);
  ASSERT_EQ(r.report.short_tracks.size(), 1u);
  EXPECT_EQ(r.report.short_tracks[0].track, "3");
  EXPECT_EQ(r.report.short_tracks[0].rows, 9u);
  ASSERT_EQ(r.set.trajectories.size(), 1u);
  EXPECT_EQ(r.set.trajectories[0].id, "1");

  // The bounds are options: a looser speed keeps track 2, fewer frames keep track 3.
  o.max_speed_mps = 5.0;
  o.min_frames = 9;
  EXPECT_EQ(join(det, kLog, o).set.trajectories.size(), 3u);
  // Nothing left is an error that gives the counts.
  o = {};
  o.object = "cotton";
  o.min_frames = 100;
  EXPECT_NE(error_of(det, kLog, o)
                .find("d.csv: no trajectory left to write (3 of 4 tracks not of type 'cotton', "
                      "1 shorter than 100 frames)"),
            std::string::npos)
      << error_of(det, kLog, o);
}

TEST(TrackJoin, TheTypeOfATrackIsItsLastRowsVote) {
  // detect's object column is the vote so far: the first rows of a track may differ.
  std::map<int, std::string> t = track_rows("1", "cotton", 0, 20, 0.2, 0.1, 0.3, 0.0);
  t[0] = row(0, "1", "tracer", 0.2, 0.1);
  const TrackJoinResult r = join(detections({t}), kLog);
  ASSERT_EQ(r.set.trajectories.size(), 1u);
  EXPECT_EQ(r.set.trajectories[0].object, "cotton");
}

TEST(TrackJoin, AReusedIdIsAnErrorNamingTheLine) {
  // Track 1 ends at frame 20; 2 takes its place; "1" comes back 9 frames later (> 8 missed).
  const std::string det = detections({track_rows("1", "tracer", 0, 20, 0.2, 0.1, 0.3, 0.0),
                                      track_rows("2", "tracer", 21, 40, 0.35, 0.1, 0.3, 0.0),
                                      track_rows("1", "tracer", 30, 50, -0.5, 0.3, 0.0, 0.0)});
  const std::string e = error_of(det, kLog);
  EXPECT_NE(e.find("d.csv:33: column 'id': track '1' reappears in frame 30 after 9 frames without "
                   "a detection (last in frame 20, line 22)"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("reused id"), std::string::npos) << e;
  // Up to max_missed_frames missed frames are the same track; the limit is an option.
  TrackJoinOptions o;
  o.max_missed_frames = 9;
  EXPECT_EQ(error_of(det, kLog, o), "");
}

TEST(TrackJoin, ALogThatStartsAfterTheFirstFrameIsAnError) {
  const std::string det = detections({track_rows("1", "tracer", 0, 20, 0.2, 0.1, 0.3, 0.0)});
  const std::string e = error_of(det, "t,pan_deg,tilt_deg\n# late\n0.01,0,10\n");
  EXPECT_NE(e.find("n.csv:3: column 't': the first command is at 0.010000 s, after the "
                   "recording's first frame (d.csv:2, frame 0 at 0.000000 s)"),
            std::string::npos)
      << e;
}

TEST(TrackJoin, ALogOnAnotherClockJoinsWithItsOffset) {
  // The same log with every time 100 s earlier (a servo log started at its own zero): with
  // clock_offset_s = 100 each row takes the same command as with the camera's clock, and the
  // written times stay the camera's.
  const std::string det = detections({track_rows("1", "tracer", 0, 79, 0.2, 0.1, 0.3, 0.0)});
  const std::string shifted =
      "t,pan_deg,tilt_deg\n"
      "-100,30,10\n"
      "-99.5,30,10\n"
      "-99.25,60,20\n"
      "-98.5,90,40\n";
  TrackJoinOptions o;
  o.clock_offset_s = 100.0;
  const TrackJoinResult a = join(det, shifted, o), b = join(det, kLog);
  EXPECT_EQ(trajectory_csv(a.set), trajectory_csv(b.set));
  EXPECT_EQ(a.report.command_changes, b.report.command_changes);
  // Without the offset the log would have ended long before the recording: one command for all.
  const TrackJoinResult c = join(det, shifted);
  for (const TrajectorySample& sample : c.set.trajectories[0].samples) {
    EXPECT_NEAR(rad_to_deg(sample.nozzle.pan_rad), 90, 1e-12);
  }
  // A log that starts after the recording on the camera's clock says both times.
  o.clock_offset_s = 100.5;
  const std::string e = error_of(det, shifted, o);
  EXPECT_NE(e.find("the first command is at -100.000000 s (0.500000 s on the camera's clock), "
                   "after the recording's first frame"),
            std::string::npos)
      << e;
}

std::string parse_error(const std::string& text) {
  try {
    parse_detections_csv(text, "d.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(TrackJoin, DetectionErrorsNameFileLineColumnAndValue) {
  const std::string r0 = row(0, "1", "tracer", 0.1, 0.2), r1 = row(1, "1", "tracer", 0.1, 0.2);
  EXPECT_NE(parse_error(kHeader).find("d.csv: no detection after the header"), std::string::npos);
  EXPECT_NE(parse_error("frame,t,id,object,x\n0,0,1,tracer,0\n").find("missing column 'y'"),
            std::string::npos);
  EXPECT_NE(parse_error(kHeader + r1 + r0)
                .find("d.csv:3: column 'frame': expected frames in "
                      "order, got 0 after frame 1 on line 2"),
            std::string::npos);
  EXPECT_NE(parse_error(kHeader + r0 + "0,0.001,2,tracer,0,0,1,1\n")
                .find("d.csv:3: column 't': frame 0 is at 0.000000 s on line 2, got 0.001"),
            std::string::npos);
  EXPECT_NE(parse_error(kHeader + r0 + "1,0.000000,1,tracer,0,0,1,1\n")
                .find("d.csv:3: column 't': expected a time after frame 0's 0.000000 s (line 2), "
                      "got 0.000000"),
            std::string::npos);
  EXPECT_NE(parse_error(kHeader + r0 + r0)
                .find("d.csv:3: column 'id': track '1' is detected "
                      "twice in frame 0 (also on line 2)"),
            std::string::npos);
  EXPECT_NE(parse_error(kHeader + "0,0,1,tracer,nan,0,1,1\n")
                .find("d.csv:2: column 'x': expected a finite number, got 'nan'"),
            std::string::npos);
  EXPECT_NE(parse_error(kHeader + "0,0,1,tracer,0,0,1,inf\n").find("d.csv:2: column 'y_px'"),
            std::string::npos);
  EXPECT_NE(parse_error(kHeader + "1.5,0,1,tracer,0,0,1,1\n")
                .find("d.csv:2: column 'frame': expected a frame index (a whole number >= 0), "
                      "got 1.5"),
            std::string::npos);
  EXPECT_NE(parse_error(kHeader + "0,0,,tracer,0,0,1,1\n").find("d.csv:2: column 'id': empty"),
            std::string::npos);
  EXPECT_NE(parse_error(kHeader + "0,0,1,pebble,0,0,1,1\n").find("unknown object type 'pebble'"),
            std::string::npos);
  // A render's truth.csv has the same columns; pixels are optional.
  EXPECT_EQ(parse_error("frame,t,id,object,x,y\n0,0,t1,tracer,0.1,0.2\n"), "");
}

TEST(TrackJoin, OptionsAreCheckedByField) {
  auto field_of = [](TrackJoinOptions o) -> std::string {
    try {
      o.validate();
    } catch (const FieldError& e) {
      return e.field();
    }
    return "";
  };
  TrackJoinOptions o;
  EXPECT_EQ(field_of(o), "");
  o.min_frames = 1;
  EXPECT_EQ(field_of(o), "track_join.min_frames");
  o = {};
  o.max_speed_mps = std::nan("");
  EXPECT_EQ(field_of(o), "track_join.max_speed_mps");
  o = {};
  o.max_missed_frames = -1;
  EXPECT_EQ(field_of(o), "track_join.max_missed_frames");
  o = {};
  o.object = "pebble";
  EXPECT_EQ(field_of(o), "track_join.object");
  o = {};
  o.clock_offset_s = INFINITY;
  EXPECT_EQ(field_of(o), "track_join.clock_offset_s");
}

TEST(TrackJoin, SameInputSameOutput) {
  const std::string det = detections({track_rows("7", "tracer", 0, 79, 0.2, 0.1, 0.3, 0.0),
                                      track_rows("3", "cotton", 5, 70, -0.3, 0.4, 0.0, -0.2)});
  TrackJoinOptions o;
  o.cut_trials = true;
  EXPECT_EQ(trajectory_csv(join(det, kLog, o).set), trajectory_csv(join(det, kLog, o).set));
  // Trajectories in the order of their tracks' first rows, not of their ids.
  EXPECT_EQ(join(det, kLog).set.trajectories[0].id, "7");
}

}  // namespace
}  // namespace airtwin
