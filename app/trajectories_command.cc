// airtwin trajectories: a camera's tracks (detect's detections.csv, or a render's truth.csv) and
// the nozzle's command log in, the trajectory CSV that identify and discrepancy read out
// (models/track_join.h, docs/data_formats.md). On stdout what was read, kept and dropped.

#include <cstdio>
#include <memory>
#include <string>

#include "app/cli_common.h"
#include "app/commands.h"
#include "common/errors.h"
#include "models/track_join.h"
#include "models/trajectory_data.h"

namespace airtwin::cli {
namespace {

struct TrajectoriesArgs {
  std::string detections;
  std::string nozzle;
  std::string out;
  TrackJoinOptions options;
};

constexpr std::initializer_list<FlagOf> kJoinFlags = {
    {"track_join.min_frames", "--min-frames"},
    {"track_join.max_speed_mps", "--max-speed"},
    {"track_join.max_missed_frames", "--max-missed"},
    {"track_join.object", "--object"},
    {"track_join.clock_offset_s", "--clock-offset"}};

// The ids of some dropped tracks, for the report: the first few, then how many more.
std::string ids_of(const std::vector<DroppedTrack>& tracks) {
  std::string out;
  for (size_t i = 0; i < tracks.size() && i < 8; ++i) out += (i ? " " : "") + tracks[i].track;
  if (tracks.size() > 8) out += " and " + std::to_string(tracks.size() - 8) + " more";
  return out;
}

void print_report(const TrackJoinReport& r, const TrajectoriesArgs& a) {
  const TrackJoinOptions& o = a.options;
  std::printf("trajectories: %zu detections in %zu tracks, %zu nozzle commands (%zu periods)\n",
              r.rows, r.tracks, r.commands, r.command_changes);
  if (r.other_object_tracks > 0) {
    std::printf("  not %s: %zu tracks (%zu rows)\n", o.object.c_str(), r.other_object_tracks,
                r.other_object_rows);
  }
  if (!r.jumps.empty()) {
    std::printf("  dropped, a step faster than %g m/s: %zu tracks (%s)", o.max_speed_mps,
                r.jumps.size(), ids_of(r.jumps).c_str());
    std::printf("; the first: track %s, %.2f m/s into frame %lld\n", r.jumps[0].track.c_str(),
                r.jumps[0].speed_mps, static_cast<long long>(r.jumps[0].frame));
  }
  if (!r.short_tracks.empty()) {
    size_t rows = 0;
    for (const DroppedTrack& d : r.short_tracks) rows += d.rows;
    std::printf("  dropped, shorter than %d frames: %zu tracks, %zu rows (%s)\n", o.min_frames,
                r.short_tracks.size(), rows, ids_of(r.short_tracks).c_str());
  }
  if (r.gaps > 0 || r.trial_cuts > 0) {
    std::printf("  cut: %zu at missed frames, %zu at command changes\n", r.gaps, r.trial_cuts);
  }
  if (r.short_pieces > 0) {
    std::printf("  dropped, pieces shorter than %d frames: %zu pieces, %zu rows\n", o.min_frames,
                r.short_pieces, r.short_piece_rows);
  }
  std::printf("  wrote %zu trajectories (%s), %zu rows, to %s\n", r.trajectories,
              o.cut_trials ? "one per trial" : "closed-loop segments", r.samples, a.out.c_str());
}

void run_trajectories(const TrajectoriesArgs& a) {
  // Flags first (exit 2), then the files (exit 1).
  with_flags(kJoinFlags, [&] { a.options.validate(); });
  ensure_parent_dir(a.out);
  const DetectionTable detections = read_detections_csv(a.detections);
  const NozzleLog nozzle = read_nozzle_log(a.nozzle);
  const TrackJoinResult result = join_tracks(detections, nozzle, a.options);
  write_text_file(a.out, trajectory_csv(result.set));
  print_report(result.report, a);
}

}  // namespace

void add_trajectories_command(CLI::App& app) {
  auto args = std::make_shared<TrajectoriesArgs>();
  CLI::App* sub = app.add_subcommand(
      "trajectories",
      "Join a camera's tracks with the nozzle's command log into the trajectory CSV that\n"
      "identify and discrepancy read: DETECTIONS.csv as `detect` writes it\n"
      "(frame,t,id,object,x,y[,x_px,y_px]; a render's truth.csv too), NOZZLE.csv a log\n"
      "t,pan_deg,tilt_deg of the commands, each in force from its time on (a rig's servo log;\n"
      "`run` and `render` write DIR/nozzle.csv). Each row takes the command in force at its\n"
      "frame's time. Tracks are cut at missed frames; --trials cuts them at command changes too.\n"
      "Tracks with a jump or too few frames are dropped and counted on stdout.\n"
      "docs/data_formats.md, docs/identification.md.");
  sub->add_option("DETECTIONS", args->detections, "Detections CSV (detect --out)")->required();
  sub->add_option("--nozzle", args->nozzle, "Nozzle command log CSV (t,pan_deg,tilt_deg)")
      ->required();
  sub->add_option("--out", args->out, "Output trajectory CSV")->required();
  TrackJoinOptions& o = args->options;
  sub->add_option("--object", o.object, "Keep only tracks of this type (tracer | cotton)");
  sub->add_flag("--trials", o.cut_trials,
                "Cut Appendix D trials: a trajectory per track and command period (the frames\n"
                "from one command change to the next); default: closed-loop segments, the\n"
                "commands a track lived through, one per row");
  sub->add_option("--min-frames", o.min_frames,
                  "Tracks and pieces with fewer frames are dropped (and counted)")
      ->capture_default_str();
  sub->add_option("--max-speed", o.max_speed_mps,
                  "A track with a step faster than this (m/s) between consecutive detections is\n"
                  "dropped as a wrong association (and counted)")
      ->capture_default_str();
  sub->add_option("--max-missed", o.max_missed_frames,
                  "detect's --max-missed: a track's id back after a longer gap is a reused id, an\n"
                  "error")
      ->capture_default_str();
  sub->add_option("--clock-offset", o.clock_offset_s,
                  "Seconds the nozzle log's clock runs behind the camera's: a command logged at t\n"
                  "acted at t + offset on the detections' clock")
      ->capture_default_str();
  sub->callback([args] { run_trajectories(*args); });
}

}  // namespace airtwin::cli
