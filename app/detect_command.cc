// airtwin detect: the detection pipeline on recorded frames. Reads a folder of images (what
// `airtwin render` writes to DIR/frames/) or a video, detects tracers and cotton wads in every
// frame (vision/object_detector.h), places them on the floor through the calibrated camera
// (`airtwin calibrate`), tracks them (vision/tracker.h), and writes detections.csv
// (frame,t,id,object,x,y,x_px,y_px; docs/data_formats.md). docs/vision.md.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/cli_common.h"
#include "app/commands.h"
#include "app/progress.h"
#include "common/csv.h"
#include "common/errors.h"
#include "vision/calibrated_camera.h"
#include "vision/frame_source.h"
#include "vision/object_detector.h"
#include "vision/tracker.h"

namespace airtwin::cli {
namespace {

struct DetectArgs {
  std::string input;
  std::string calib;
  std::string out;
  std::string times;
  double fps = 40.0;
  double max_jump_m = 0.05;
  int max_missed = 8;
  bool quiet = false;
  CLI::Option* fps_option = nullptr;
};

// The frame rate of a video written by `airtwin render --video` (every stride-th camera frame):
// its sidecar F.json says so. nullopt without a sidecar; InputError for a sidecar without the
// numbers.
std::optional<double> sidecar_fps(const std::string& video) {
  const std::string path = video + ".json";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return std::nullopt;
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(read_text_file(path));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not a video sidecar (" + e.what() + ")");
  }
  if (!j.contains("camera_rate_hz") || !j["camera_rate_hz"].is_number() || !j.contains("stride") ||
      !j["stride"].is_number_integer() || !(j["camera_rate_hz"].get<double>() > 0) ||
      j["stride"].get<int>() < 1) {
    throw InputError(path +
                     ": a video sidecar needs camera_rate_hz > 0 and an integer stride >= 1");
  }
  return j["camera_rate_hz"].get<double>() / j["stride"].get<int>();
}

void run_detect(const DetectArgs& a) {
  // Flags first: a bad value is a usage error before any work.
  require_range(a.fps, 1e-3, 1e6, "--fps", "a frame rate > 0 in Hz");
  require_range(a.max_jump_m, 1e-4, 10.0, "--max-jump", "a distance > 0 in m");
  require_range(a.max_missed, 0, 10000, "--max-missed", "a number of frames >= 0");

  // The camera, the frames and their times (a render's video sidecar gives its rate unless
  // --fps does).
  const CalibratedCamera camera = CalibratedCamera::read(a.calib);
  FrameSourceOptions source_options;
  source_options.fps = a.fps;
  source_options.times_path = a.times;
  std::string rate_from = "--fps";
  std::error_code ec;
  if (a.fps_option->count() == 0 && std::filesystem::is_regular_file(a.input, ec)) {
    if (const auto fps = sidecar_fps(a.input)) {
      source_options.fps = *fps;
      rate_from = a.input;
      rate_from += ".json";
    }
  }
  FrameSource source = FrameSource::open(a.input, source_options);

  ObjectDetector detector(camera);
  TrackerOptions tracker_options;
  tracker_options.max_jump_m = a.max_jump_m;
  tracker_options.max_missed_frames = a.max_missed;
  tracker_options.image_width_px = camera.width_px;
  tracker_options.image_height_px = camera.height_px;
  Tracker tracker(tracker_options);

  std::unique_ptr<Progress> progress;
  const std::optional<int64_t> count = source.frame_count();
  if (!a.quiet && count && *count >= 40) {
    progress = std::make_unique<Progress>("detect", "frames", static_cast<int>(*count));
  }

  // Frame by frame: detect, track, one row per detection in id order.
  std::string csv = kDetectionsCsvHeader;
  Frame frame;
  int64_t frames = 0, merged_blobs = 0;
  while (source.next(frame)) {
    if (frame.bgr.cols != camera.width_px || frame.bgr.rows != camera.height_px) {
      throw InputError(a.input + ": " + frame.name + " is " + std::to_string(frame.bgr.cols) +
                       " x " + std::to_string(frame.bgr.rows) + " px, but " + a.calib +
                       " calibrates a " + std::to_string(camera.width_px) + " x " +
                       std::to_string(camera.height_px) + " px camera");
    }
    const std::vector<Detection>& detections = detector.detect(frame.bgr);
    merged_blobs += detector.stats().merged_blobs;
    tracker.update(frame.t_s, detections);
    csv += detection_rows_csv(tracker, detections, frame.index, frame.t_s);
    ++frames;
    if (progress) progress->update(static_cast<int>(frames));
  }
  if (progress) progress->finish();
  write_text_file(a.out, csv);

  // The summary.
  const TrackerCounters& c = tracker.counters();
  char times[512];
  if (source.times_path().empty()) {
    std::snprintf(times, sizeof times, "%g Hz from %s", source.fps(), rate_from.c_str());
  } else {
    std::snprintf(times, sizeof times, "times from %s", source.times_path().c_str());
  }
  std::printf(
      "detect: %lld frames (%s, %s), %lld detections, %lld tracks (%lld lost, %lld left the view, "
      "%zu at the end), %lld missed track-frames, %lld merges (track-frames hidden in another "
      "object's blob), %lld merged blobs split; wrote %s\n",
      static_cast<long long>(frames), source.kind(), times, static_cast<long long>(c.detections),
      static_cast<long long>(c.new_tracks), static_cast<long long>(c.lost),
      static_cast<long long>(c.left_view), tracker.tracks().size(),
      static_cast<long long>(c.missed), static_cast<long long>(c.merged),
      static_cast<long long>(merged_blobs), a.out.c_str());
}

}  // namespace

void add_detect_command(CLI::App& app) {
  auto args = std::make_shared<DetectArgs>();
  CLI::App* sub = app.add_subcommand(
      "detect",
      "Detect and track the objects in recorded frames: tracers (circle detection) and cotton\n"
      "wads (blobs), placed on the floor through a calibrated camera ('airtwin calibrate'), ids\n"
      "kept across frames. INPUT is a folder of PNG/JPEG frames (name order; 'airtwin render'\n"
      "writes DIR/frames/) or a video. Writes frame,t,id,object,x,y,x_px,y_px. docs/vision.md.");
  sub->add_option("INPUT", args->input, "Folder of frames or video file")->required();
  sub->add_option("--calib", args->calib, "Calibrated camera YAML ('airtwin calibrate --out')")
      ->required();
  sub->add_option("--out", args->out, "Output detections CSV")->required();
  args->fps_option =
      sub->add_option("--fps", args->fps,
                      "Frame rate (Hz): frame k is at k / fps; default 40, or a render video's "
                      "sidecar rate")
          ->capture_default_str();
  sub->add_option("--times", args->times,
                  "CSV frame,t giving each frame's time (s); default: times.csv in the folder if "
                  "present, else from --fps");
  sub->add_option("--max-jump", args->max_jump_m,
                  "Farthest an object moves between frames (m): the tracker's gate")
      ->capture_default_str();
  sub->add_option("--max-missed", args->max_missed, "Frames a track survives without a detection")
      ->capture_default_str();
  sub->add_flag("--quiet", args->quiet, "No progress on stderr");
  sub->callback([args] { run_detect(*args); });
}

}  // namespace airtwin::cli
