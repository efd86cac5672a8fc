#pragma once
// Camera frames as an H.264 MP4 video for people (the paper's supplementary video shows the rig's
// camera; this shows the twin's). Frames come at the camera's rate in simulation time (40 Hz,
// section II-A) and are played back at 40 fps, so with every frame kept one second of video is one
// second of simulated time. A stride k keeps every k-th camera frame: the video then runs k times
// faster than the simulation (its time scale, reported in the sidecar and by close()).
//
// Encoding (OpenCV's FFmpeg backend, fourcc 'avc1', ~19 ms per 1024 x 1024 frame) runs on a worker
// thread of its own behind a bounded queue: write() copies the frame into the queue and returns,
// and waits only when the queue is full (the encoder is then the bottleneck). Errors of the encoder
// are raised by the next write() or by close().
//
// MP4 metadata through OpenCV is limited, so close() also writes a JSON sidecar next to the video,
// `<file>.json`: {"fps", "stride", "frames", "sim_seconds", ...} (docs/data_formats.md).
//
// One VideoWriter is used from one thread (write() and close() are not reentrant); the worker is
// internal.

#include <cstdint>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

namespace airtwin {

struct VideoOptions {
  /// Rate (Hz, simulation time) of the frames given to write(): the camera's 40 Hz.
  double camera_rate_hz = 40.0;
  /// Playback rate of the file (frames per second).
  double fps = 40.0;
  /// Keep every stride-th frame given to write() (the first always), >= 1.
  int stride = 1;
  /// Frame size (px); every frame must be this size, 8-bit BGR.
  int width_px = 1024;
  int height_px = 1024;
  /// Frames that may wait for the encoder before write() blocks, >= 1.
  int queue_capacity = 8;
  /// FourCC of the codec: "avc1" (H.264) by default; "mp4v" (MPEG-4 part 2) is ~4x faster to
  /// encode and ~7x larger.
  std::string fourcc = "avc1";

  /// Throws InputError naming the option when a value is out of range.
  void validate() const;
  /// Simulated seconds per second of video (1 = real time): fps video frames, each standing for
  /// stride / camera_rate_hz simulated seconds.
  double time_scale() const { return fps * stride / camera_rate_hz; }
};

/// What a finished video holds.
struct VideoSummary {
  std::string path;
  int64_t frames_offered = 0;  ///< frames given to write()
  int64_t frames_written = 0;  ///< frames encoded into the file (every stride-th)
  double sim_seconds = 0.0;    ///< simulated time the offered frames span: offered / camera rate
  double video_seconds = 0.0;  ///< playback length: written / fps
  double time_scale = 1.0;     ///< simulated seconds per video second
  double encode_ms_per_frame = 0.0;  ///< mean wall-clock time of the encoder per written frame
};

class VideoWriter {
 public:
  /// Opens `path` (an .mp4; its folder must exist) and starts the encoder thread. Throws
  /// InputError for bad options or when the file cannot be opened for this codec (naming both).
  VideoWriter(const std::string& path, const VideoOptions& options = {});
  /// Closes the video if close() was not called (errors are then only printed to stderr).
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  /// Offers the next camera frame (CV_8UC3 BGR, width_px x height_px). Every stride-th one is
  /// copied into the queue; waits only while the queue is full. Returns true when the frame was
  /// kept. Throws InputError naming the file and the frame for a wrong size or type, and rethrows
  /// an encoder failure; throws std::logic_error after close().
  bool write(const cv::Mat& bgr);

  /// Encodes what is queued, finalises the MP4, writes `<path>.json` and reports. Throws
  /// InputError when encoding failed or the sidecar cannot be written. A second call returns the
  /// same summary.
  VideoSummary close();

  const std::string& path() const;
  const VideoOptions& options() const;
  int64_t frames_offered() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The sidecar's text for a summary and its options (JSON, one object).
std::string video_sidecar_json(const VideoSummary& summary, const VideoOptions& options);

}  // namespace airtwin
