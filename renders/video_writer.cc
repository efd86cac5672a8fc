#include "renders/video_writer.h"

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include <opencv2/videoio.hpp>

#include "common/errors.h"

namespace airtwin {
namespace {

std::string num(double v) {
  std::ostringstream out;
  out << std::setprecision(10) << v;
  return out.str();
}

}  // namespace

void VideoOptions::validate() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw InputError("video options: " + what);
  };
  require(std::isfinite(camera_rate_hz) && camera_rate_hz > 0 && camera_rate_hz <= 10000,
          "camera_rate_hz must be in (0, 10000] Hz, got " + num(camera_rate_hz));
  require(std::isfinite(fps) && fps > 0 && fps <= 1000,
          "fps must be in (0, 1000], got " + num(fps));
  require(stride >= 1 && stride <= 100000,
          "stride must be in [1, 100000], got " + std::to_string(stride));
  // H.264 in MP4 stores 4:2:0 chroma: both sides must be even.
  require(width_px >= 16 && height_px >= 16 && width_px <= 8192 && height_px <= 8192 &&
              width_px % 2 == 0 && height_px % 2 == 0,
          "the frame size must be even and in [16, 8192] px, got " + std::to_string(width_px) +
              " x " + std::to_string(height_px));
  require(queue_capacity >= 1 && queue_capacity <= 1024,
          "queue_capacity must be in [1, 1024], got " + std::to_string(queue_capacity));
  require(fourcc.size() == 4, "fourcc must be 4 characters, got '" + fourcc + "'");
}

std::string video_sidecar_json(const VideoSummary& s, const VideoOptions& o) {
  // Hand-written (a handful of numbers); keys in a fixed order, so the same run gives the same
  // bytes.
  std::ostringstream out;
  out << "{\n"
      << "  \"fps\": " << num(o.fps) << ",\n"
      << "  \"stride\": " << o.stride << ",\n"
      << "  \"frames\": " << s.frames_written << ",\n"
      << "  \"sim_seconds\": " << num(s.sim_seconds) << ",\n"
      << "  \"camera_rate_hz\": " << num(o.camera_rate_hz) << ",\n"
      << "  \"frames_offered\": " << s.frames_offered << ",\n"
      << "  \"time_scale\": " << num(s.time_scale) << ",\n"
      << "  \"video_seconds\": " << num(s.video_seconds) << ",\n"
      << "  \"width_px\": " << o.width_px << ",\n"
      << "  \"height_px\": " << o.height_px << ",\n"
      << "  \"codec\": \"" << o.fourcc << "\"\n"
      << "}\n";
  return out.str();
}

struct VideoWriter::Impl {
  std::string path;
  VideoOptions options;
  cv::VideoWriter writer;

  // The queue between write() and the encoder thread, and recycled frame buffers.
  std::mutex mutex;
  std::condition_variable frame_ready, slot_free;
  std::deque<cv::Mat> queue;
  std::vector<cv::Mat> spare;
  bool stopping = false;
  std::string encoder_error;  // set once by the worker; frames after it are dropped
  int64_t encoded = 0;
  double encode_seconds = 0.0;
  std::thread worker;

  int64_t offered = 0;
  bool closed = false;
  VideoSummary summary;

  // The encoder thread: takes frames in order until close() asks it to stop and the queue is
  // empty.
  void run() {
    for (;;) {
      cv::Mat frame;
      {
        std::unique_lock lock(mutex);
        frame_ready.wait(lock, [&] { return stopping || !queue.empty(); });
        if (queue.empty()) return;
        frame = std::move(queue.front());
        queue.pop_front();
      }
      slot_free.notify_one();
      bool failed;
      {
        std::lock_guard lock(mutex);
        failed = !encoder_error.empty();
      }
      // Encode outside the lock: write() may queue the next frame meanwhile.
      std::string error;
      double seconds = 0.0;
      if (!failed) {
        const auto start = std::chrono::steady_clock::now();
        try {
          writer.write(frame);
        } catch (const cv::Exception& e) {
          error = e.what();
        } catch (const std::exception& e) {
          error = e.what();
        }
        seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      }
      {
        std::lock_guard lock(mutex);
        if (!error.empty() && encoder_error.empty()) encoder_error = error;
        if (!failed && error.empty()) {
          ++encoded;
          encode_seconds += seconds;
        }
        spare.push_back(std::move(frame));
      }
      slot_free.notify_one();
    }
  }

  // Stops the worker after the queued frames and finalises the file (idempotent).
  void stop() {
    if (!worker.joinable()) return;
    {
      std::lock_guard lock(mutex);
      stopping = true;
    }
    frame_ready.notify_all();
    worker.join();
    writer.release();
  }
};

VideoWriter::VideoWriter(const std::string& path, const VideoOptions& options)
    : impl_(std::make_unique<Impl>()) {
  options.validate();
  impl_->path = path;
  impl_->options = options;
  // A missing folder is the common mistake; say so rather than "cannot open".
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent)) {
    throw InputError(path + ": cannot open the video for writing: folder '" + parent.string() +
                     "' does not exist");
  }
  const std::string& f = options.fourcc;
  bool opened = false;
  std::string reason;
  try {
    opened =
        impl_->writer.open(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc(f[0], f[1], f[2], f[3]),
                           options.fps, cv::Size(options.width_px, options.height_px), true);
  } catch (const cv::Exception& e) {
    reason = std::string(": ") + e.what();
  }
  if (!opened) {
    throw InputError(path + ": cannot open the video for writing with codec '" + f +
                     "' (OpenCV's FFmpeg backend)" + reason);
  }
  impl_->worker = std::thread([impl = impl_.get()] { impl->run(); });
}

VideoWriter::~VideoWriter() {
  if (!impl_ || impl_->closed) return;
  try {
    close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "airtwin: error: %s\n", e.what());
  }
}

bool VideoWriter::write(const cv::Mat& bgr) {
  Impl& s = *impl_;
  if (s.closed) throw std::logic_error("VideoWriter::write after close()");
  // Every frame offered must fit the file, whether it is kept or not.
  if (bgr.type() != CV_8UC3 || bgr.cols != s.options.width_px || bgr.rows != s.options.height_px) {
    throw InputError(s.path + ": frame " + std::to_string(s.offered) + " is " +
                     std::to_string(bgr.cols) + " x " + std::to_string(bgr.rows) + " px with " +
                     std::to_string(bgr.channels()) + " channel(s) of depth " +
                     std::to_string(bgr.depth()) + ", expected " +
                     std::to_string(s.options.width_px) + " x " +
                     std::to_string(s.options.height_px) + " px 8-bit BGR");
  }
  const int64_t index = s.offered++;
  if (index % s.options.stride != 0) return false;

  // Wait for a free slot (only when the encoder is behind), then take a recycled buffer.
  cv::Mat slot;
  {
    std::unique_lock lock(s.mutex);
    s.slot_free.wait(lock, [&] {
      return static_cast<int>(s.queue.size()) < s.options.queue_capacity ||
             !s.encoder_error.empty();
    });
    if (!s.encoder_error.empty()) {
      throw InputError(s.path + ": the video encoder failed: " + s.encoder_error);
    }
    if (!s.spare.empty()) {
      slot = std::move(s.spare.back());
      s.spare.pop_back();
    }
  }
  bgr.copyTo(slot);  // outside the lock; reallocates only a fresh buffer
  {
    std::lock_guard lock(s.mutex);
    s.queue.push_back(std::move(slot));
  }
  s.frame_ready.notify_one();
  return true;
}

VideoSummary VideoWriter::close() {
  Impl& s = *impl_;
  if (s.closed) return s.summary;
  s.closed = true;
  s.stop();
  if (!s.encoder_error.empty()) {
    throw InputError(s.path + ": the video encoder failed: " + s.encoder_error);
  }
  VideoSummary& sum = s.summary;
  sum.path = s.path;
  sum.frames_offered = s.offered;
  sum.frames_written = s.encoded;
  sum.sim_seconds = static_cast<double>(s.offered) / s.options.camera_rate_hz;
  sum.video_seconds = static_cast<double>(s.encoded) / s.options.fps;
  sum.time_scale = s.options.time_scale();
  sum.encode_ms_per_frame = s.encoded > 0 ? 1e3 * s.encode_seconds / s.encoded : 0.0;

  // The sidecar, next to the video.
  const std::string sidecar = s.path + ".json";
  std::ofstream out(sidecar, std::ios::binary | std::ios::trunc);
  out << video_sidecar_json(sum, s.options);
  out.close();
  if (!out) throw InputError(sidecar + ": cannot write the video sidecar");
  return sum;
}

const std::string& VideoWriter::path() const { return impl_->path; }
const VideoOptions& VideoWriter::options() const { return impl_->options; }
int64_t VideoWriter::frames_offered() const { return impl_->offered; }

}  // namespace airtwin
