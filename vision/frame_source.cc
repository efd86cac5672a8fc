#include "vision/frame_source.h"

#include <stdlib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <system_error>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "common/csv.h"
#include "common/errors.h"

namespace airtwin {
namespace fs = std::filesystem;

namespace {

bool is_image_name(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tif" ||
         ext == ".tiff";
}

// Frames as the detector wants them: 8-bit BGR (a BGR image changes hands without a copy).
void to_bgr(cv::Mat& in, cv::Mat& out) {
  if (in.type() == CV_8UC3) {
    std::swap(in, out);
  } else if (in.type() == CV_8UC1) {
    cv::cvtColor(in, out, cv::COLOR_GRAY2BGR);
  } else if (in.type() == CV_8UC4) {
    cv::cvtColor(in, out, cv::COLOR_BGRA2BGR);
  } else {
    in.convertTo(out, CV_8U);
    if (out.channels() == 1) cv::cvtColor(out, out, cv::COLOR_GRAY2BGR);
  }
}

}  // namespace

std::vector<std::string> list_image_files(const std::string& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw InputError(folder + ": no such folder");
  std::vector<std::string> files;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_regular_file(ec) && is_image_name(it->path())) files.push_back(it->path().string());
  }
  if (ec) throw InputError(folder + ": cannot list the folder (" + ec.message() + ")");
  if (files.empty()) {
    throw InputError(folder + ": no image files (png, jpg, jpeg, bmp, tif, tiff) in the folder");
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<double> read_frame_times(const std::string& path) {
  const CsvTable table = CsvTable::read_file(path, {"frame", "t"});
  if (table.rows() == 0) throw InputError(path + ": no frame times");
  std::vector<double> times;
  for (size_t row = 0; row < table.rows(); ++row) {
    // Frames 0, 1, 2, ... in order; times finite and increasing.
    const double frame = table.number(row, "frame");
    if (frame != static_cast<double>(row)) {
      throw InputError(table.where(row) + ": column 'frame': expected " + std::to_string(row) +
                       " (frames numbered from 0 in order), got " + table.text(row, "frame"));
    }
    const double t = table.number(row, "t");
    if (!times.empty() && !(t > times.back())) {
      throw InputError(table.where(row) + ": column 't': times must increase, got " +
                       table.text(row, "t") + " after " + std::to_string(times.back()));
    }
    times.push_back(t);
  }
  return times;
}

struct FrameSource::Impl {
  std::string path;
  bool video = false;
  std::vector<std::string> files;  // folder
  cv::VideoCapture capture;        // video
  std::optional<int64_t> count;
  double fps = 40.0;
  std::vector<double> times;  // from a times file; empty: from fps
  std::string times_path;
  int64_t next_index = 0;
  cv::Size size;
  cv::Mat decoded;
};

FrameSource::FrameSource(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
FrameSource::~FrameSource() = default;
FrameSource::FrameSource(FrameSource&&) noexcept = default;
FrameSource& FrameSource::operator=(FrameSource&&) noexcept = default;

FrameSource FrameSource::open(const std::string& path, const FrameSourceOptions& options) {
  if (!(std::isfinite(options.fps) && options.fps > 0)) {
    throw InputError("frame source: fps must be finite and > 0, got " +
                     std::to_string(options.fps));
  }
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->fps = options.fps;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path + ": no such file or folder");

  if (fs::is_directory(path, ec)) {
    // A folder: its images by name, and its times.csv if it has one.
    impl->files = list_image_files(path);
    impl->count = static_cast<int64_t>(impl->files.size());
    impl->times_path = options.times_path;
    if (impl->times_path.empty() && fs::is_regular_file(fs::path(path) / "times.csv", ec)) {
      impl->times_path = (fs::path(path) / "times.csv").string();
    }
  } else {
    // A video: FFmpeg must open it. FFmpeg logs its own complaints ("moov atom not found") on
    // stderr, where only our one-line error belongs: OpenCV's FFmpeg backend reads its log level
    // from OPENCV_FFMPEG_LOGLEVEL when it first loads; quiet (-8) unless the user set one.
    impl->video = true;
    ::setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);
    impl->times_path = options.times_path;
    bool opened = false;
    try {
      opened = impl->capture.open(path, cv::CAP_FFMPEG);
    } catch (const cv::Exception&) {
      opened = false;
    }
    if (!opened) throw InputError(path + ": cannot open as a video (FFmpeg cannot read it)");
    const double n = impl->capture.get(cv::CAP_PROP_FRAME_COUNT);
    if (std::isfinite(n) && n > 0) impl->count = static_cast<int64_t>(std::llround(n));
  }
  if (!impl->times_path.empty()) impl->times = read_frame_times(impl->times_path);
  FrameSource source(std::move(impl));
  return source;
}

bool FrameSource::next(Frame& frame) {
  Impl& s = *impl_;
  const int64_t k = s.next_index;
  // Decode the next image.
  if (s.video) {
    bool read = false;
    try {
      read = s.capture.read(s.decoded);
    } catch (const cv::Exception&) {
      read = false;
    }
    if (!read || s.decoded.empty()) {
      if (k == 0) throw InputError(s.path + ": the video has no decodable frame");
      return false;
    }
    frame.name = "frame " + std::to_string(k);
  } else {
    if (k >= static_cast<int64_t>(s.files.size())) return false;
    const std::string& file = s.files[static_cast<size_t>(k)];
    try {
      s.decoded = cv::imread(file, cv::IMREAD_COLOR);
    } catch (const cv::Exception&) {
      s.decoded.release();
    }
    if (s.decoded.empty()) throw InputError(file + ": cannot decode the image");
    frame.name = fs::path(file).filename().string();
  }
  // Every frame the size of the first.
  if (k == 0) {
    s.size = s.decoded.size();
  } else if (s.decoded.size() != s.size) {
    throw InputError(s.path + ": " + frame.name + " is " + std::to_string(s.decoded.cols) + " x " +
                     std::to_string(s.decoded.rows) + " px, the first frame " +
                     std::to_string(s.size.width) + " x " + std::to_string(s.size.height));
  }
  // Its time.
  if (!s.times.empty()) {
    if (k >= static_cast<int64_t>(s.times.size())) {
      throw InputError(s.times_path + ": no time for frame " + std::to_string(k) + " (" +
                       frame.name + "); it lists " + std::to_string(s.times.size()) + " frames");
    }
    frame.t_s = s.times[static_cast<size_t>(k)];
  } else {
    frame.t_s = static_cast<double>(k) / s.fps;
  }
  frame.index = k;
  to_bgr(s.decoded, frame.bgr);
  ++s.next_index;
  return true;
}

std::optional<int64_t> FrameSource::frame_count() const { return impl_->count; }
const std::string& FrameSource::path() const { return impl_->path; }
const char* FrameSource::kind() const { return impl_->video ? "video" : "folder"; }
const std::string& FrameSource::times_path() const { return impl_->times_path; }
double FrameSource::fps() const { return impl_->fps; }

}  // namespace airtwin
