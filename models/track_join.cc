#include "models/track_join.h"

#include <cmath>
#include <cstdio>
#include <map>

#include "common/csv.h"
#include "common/errors.h"
#include "common/text.h"

namespace airtwin {
namespace {

std::string list_of(const std::set<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

std::string seconds(double t_s) {
  char text[64];
  std::snprintf(text, sizeof text, "%.6f s", t_s);
  return text;
}

// A track's rows (indices into the table), in time order.
struct TrackRows {
  std::string id;
  std::vector<size_t> rows;
};

}  // namespace

DetectionTable read_detections_csv(const std::string& path,
                                   const std::set<std::string>& known_objects) {
  return parse_detections_csv(read_text_file(path), path, known_objects);
}

DetectionTable parse_detections_csv(const std::string& text, const std::string& source,
                                    const std::set<std::string>& known_objects) {
  const CsvTable csv =
      CsvTable::parse(text, source, {"frame", "t", "id", "object", "x", "y"}, {"x_px", "y_px"});
  if (csv.rows() == 0) throw InputError(source + ": no detection after the header");
  DetectionTable table;
  table.source = source;
  std::map<std::string, size_t> line_in_frame;  // ids of the current frame -> their lines
  for (size_t row = 0; row < csv.rows(); ++row) {
    DetectionRow d;
    d.line = csv.line_of(row);
    // The frame: a whole number >= 0, never decreasing.
    const double frame = csv.number(row, "frame");
    if (!(frame >= 0 && frame <= 9.0e15 && frame == std::floor(frame))) {
      throw InputError(csv.where(row) +
                       ": column 'frame': expected a frame index (a whole number "
                       ">= 0), got " +
                       csv.text(row, "frame"));
    }
    d.frame = static_cast<int64_t>(frame);
    d.t_s = csv.number(row, "t");
    d.track = csv.text(row, "id");
    d.object = csv.text(row, "object");
    d.p_W = {csv.number(row, "x"), csv.number(row, "y")};
    for (const char* pixel : {"x_px", "y_px"}) {
      if (csv.has_column(pixel)) (void)csv.number(row, pixel);
    }
    if (d.track.empty()) throw InputError(csv.where(row) + ": column 'id': empty track id");
    if (!known_objects.count(d.object)) {
      throw InputError(csv.where(row) + ": column 'object': unknown object type '" + d.object +
                       "', expected one of: " + list_of(known_objects));
    }

    // Frames in order, one time per frame, times increasing from frame to frame.
    if (!table.rows.empty()) {
      const DetectionRow& last = table.rows.back();
      if (d.frame < last.frame) {
        throw InputError(csv.where(row) + ": column 'frame': expected frames in order, got " +
                         csv.text(row, "frame") + " after frame " + std::to_string(last.frame) +
                         " on line " + std::to_string(last.line));
      }
      if (d.frame == last.frame && d.t_s != last.t_s) {
        throw InputError(csv.where(row) + ": column 't': frame " + std::to_string(d.frame) +
                         " is at " + seconds(last.t_s) + " on line " + std::to_string(last.line) +
                         ", got " + csv.text(row, "t"));
      }
      if (d.frame > last.frame && !(d.t_s > last.t_s)) {
        throw InputError(csv.where(row) + ": column 't': expected a time after frame " +
                         std::to_string(last.frame) + "'s " + seconds(last.t_s) + " (line " +
                         std::to_string(last.line) + "), got " + csv.text(row, "t"));
      }
      if (d.frame > last.frame) line_in_frame.clear();
    }
    // One row per track and frame.
    const auto [it, fresh] = line_in_frame.try_emplace(d.track, d.line);
    if (!fresh) {
      throw InputError(csv.where(row) + ": column 'id': track '" + d.track +
                       "' is detected twice in frame " + std::to_string(d.frame) +
                       " (also on line " + std::to_string(it->second) + ")");
    }
    table.rows.push_back(std::move(d));
  }
  return table;
}

void TrackJoinOptions::validate(const std::set<std::string>& known_objects) const {
  if (min_frames < 2 || min_frames > 1000000) {
    throw FieldError("track_join.min_frames",
                     "expected a frame count in [2, 1000000], got " + std::to_string(min_frames));
  }
  if (!(std::isfinite(max_speed_mps) && max_speed_mps > 0 && max_speed_mps <= 1000)) {
    throw FieldError("track_join.max_speed_mps",
                     "expected a speed in (0, 1000] m/s, got " + format_short(max_speed_mps));
  }
  if (max_missed_frames < 0 || max_missed_frames > 1000000) {
    throw FieldError(
        "track_join.max_missed_frames",
        "expected a frame count in [0, 1000000], got " + std::to_string(max_missed_frames));
  }
  if (!object.empty() && !known_objects.count(object)) {
    throw FieldError("track_join.object", "unknown object type '" + object +
                                              "', expected one of: " + list_of(known_objects));
  }
  if (!(std::isfinite(clock_offset_s) && std::abs(clock_offset_s) <= 86400.0)) {
    throw FieldError("track_join.clock_offset_s",
                     "expected a time in [-86400, 86400] s, got " + format_short(clock_offset_s));
  }
}

TrackJoinResult join_tracks(const DetectionTable& detections, const NozzleLog& nozzle,
                            const TrackJoinOptions& options) {
  options.validate();
  AIRTWIN_DEMAND(!detections.rows.empty() && !nozzle.commands.empty());
  const std::vector<DetectionRow>& rows = detections.rows;
  TrackJoinResult result;
  TrackJoinReport& report = result.report;
  report.rows = rows.size();
  report.commands = nozzle.commands.size();

  // The log must cover the recording: a command in force at the first frame.
  const double offset = options.clock_offset_s;
  if (nozzle.commands.front().t_s + offset > rows.front().t_s) {
    throw InputError(
        nozzle.where(0) + ": column 't': the first command is at " +
        seconds(nozzle.commands.front().t_s) +
        (offset != 0.0
             ? " (" + seconds(nozzle.commands.front().t_s + offset) + " on the camera's clock)"
             : std::string()) +
        ", after the recording's first frame (" + detections.source + ":" +
        std::to_string(rows.front().line) + ", frame " + std::to_string(rows.front().frame) +
        " at " + seconds(rows.front().t_s) + "); expected a log that starts at or before it");
  }
  // The periods of one command: a new one at every row that changes the command.
  std::vector<size_t> period_of(nozzle.commands.size(), 0);
  for (size_t i = 1; i < nozzle.commands.size(); ++i) {
    const NozzleOrientation& a = nozzle.commands[i - 1].nozzle;
    const NozzleOrientation& b = nozzle.commands[i].nozzle;
    const bool changed = a.pan_rad != b.pan_rad || a.tilt_rad != b.tilt_rad;
    period_of[i] = period_of[i - 1] + (changed ? 1 : 0);
  }
  report.command_changes = period_of.back() + 1;

  // The tracks, in the order of their first rows; a gap longer than the tracker's coasting is a
  // reused id.
  std::vector<TrackRows> tracks;
  std::map<std::string, size_t> track_of;
  for (size_t r = 0; r < rows.size(); ++r) {
    const auto [it, fresh] = track_of.try_emplace(rows[r].track, tracks.size());
    if (fresh) tracks.push_back({rows[r].track, {}});
    TrackRows& track = tracks[it->second];
    if (!track.rows.empty()) {
      const DetectionRow& last = rows[track.rows.back()];
      const int64_t missed = rows[r].frame - last.frame - 1;
      if (missed > options.max_missed_frames) {
        throw InputError(detections.source + ":" + std::to_string(rows[r].line) +
                         ": column 'id': track '" + rows[r].track + "' reappears in frame " +
                         std::to_string(rows[r].frame) + " after " + std::to_string(missed) +
                         " frames without a detection (last in frame " +
                         std::to_string(last.frame) + ", line " + std::to_string(last.line) +
                         "); a track ends after max_missed_frames = " +
                         std::to_string(options.max_missed_frames) +
                         " missed frames and its id is never given again: a reused id");
      }
    }
    track.rows.push_back(r);
  }
  report.tracks = tracks.size();

  result.set.has_group = false;
  for (const TrackRows& track : tracks) {
    // The track's type: detect's object column is the vote of the detections so far, so the last
    // row's holds the whole track's.
    const std::string& object = rows[track.rows.back()].object;
    if (!options.object.empty() && object != options.object) {
      ++report.other_object_tracks;
      report.other_object_rows += track.rows.size();
      continue;
    }
    // A step faster than the bound: a wrong association, not motion.
    bool jumped = false;
    for (size_t k = 1; k < track.rows.size() && !jumped; ++k) {
      const DetectionRow& a = rows[track.rows[k - 1]];
      const DetectionRow& b = rows[track.rows[k]];
      const double speed = (b.p_W - a.p_W).norm() / (b.t_s - a.t_s);
      if (speed > options.max_speed_mps) {
        report.jumps.push_back({track.id, track.rows.size(), b.frame, speed});
        jumped = true;
      }
    }
    if (jumped) continue;
    if (track.rows.size() < static_cast<size_t>(options.min_frames)) {
      report.short_tracks.push_back({track.id, track.rows.size(), 0, 0.0});
      continue;
    }

    // Pieces: consecutive frames and, for trials, one command period.
    std::vector<std::vector<TrajectorySample>> pieces(1);
    long previous_period = -1;
    for (size_t k = 0; k < track.rows.size(); ++k) {
      const DetectionRow& d = rows[track.rows[k]];
      const long command = nozzle.index_at(d.t_s - offset);
      AIRTWIN_DEMAND(command >= 0);  // the log covers the first frame
      const long period = static_cast<long>(period_of[command]);
      if (k > 0) {
        const bool gap = d.frame != rows[track.rows[k - 1]].frame + 1;
        const bool cut = options.cut_trials && period != previous_period;
        if (gap) ++report.gaps;
        if (cut && !gap) ++report.trial_cuts;
        if (gap || cut) pieces.emplace_back();
      }
      previous_period = period;
      TrajectorySample s;
      s.t_s = d.t_s;
      s.p_W = d.p_W;
      s.nozzle = nozzle.commands[command].nozzle;
      pieces.back().push_back(s);
    }
    for (size_t k = 0; k < pieces.size(); ++k) {
      if (pieces[k].size() < static_cast<size_t>(options.min_frames)) {
        ++report.short_pieces;
        report.short_piece_rows += pieces[k].size();
        continue;
      }
      Trajectory t;
      t.id = pieces.size() == 1 ? track.id : track.id + "." + std::to_string(k + 1);
      t.object = object;
      t.samples = std::move(pieces[k]);
      report.samples += t.samples.size();
      result.set.trajectories.push_back(std::move(t));
    }
  }
  report.trajectories = result.set.trajectories.size();

  if (result.set.trajectories.empty()) {
    std::string why;
    if (!options.object.empty()) {
      why += std::to_string(report.other_object_tracks) + " of " + std::to_string(report.tracks) +
             " tracks not of type '" + options.object + "'";
    }
    auto add = [&](size_t n, const std::string& what) {
      if (n > 0) why += (why.empty() ? "" : ", ") + std::to_string(n) + " " + what;
    };
    add(report.jumps.size(),
        "with a step faster than " + format_short(options.max_speed_mps) + " m/s");
    add(report.short_tracks.size(),
        "shorter than " + std::to_string(options.min_frames) + " frames");
    add(report.short_pieces,
        "pieces shorter than " + std::to_string(options.min_frames) + " frames");
    throw InputError(detections.source + ": no trajectory left to write (" + why + ")");
  }
  return result;
}

}  // namespace airtwin
