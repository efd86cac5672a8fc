#pragma once
// Frames to detect objects in, with their times: a folder of images (PNG, JPEG, BMP or TIFF, in
// the order of their file names) or a video file (decoded by OpenCV's FFmpeg backend).
//
// Times: frame k is at k / fps (fps 40 by default, the rig's camera), unless a times file gives
// them: a CSV with header `frame,t` (0-based frame index, time in s, docs/data_formats.md), found
// as `times.csv` inside a folder or named explicitly. Every frame read must then be listed, and
// times must increase.
//
// Errors are InputError naming the path: a missing path, a folder without images, an image or
// video that cannot be decoded, a bad times file, frames of different sizes.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace airtwin {

struct FrameSourceOptions {
  /// Frames per second when no times file gives the times (> 0).
  double fps = 40.0;
  /// A times CSV (`frame,t`); empty: `times.csv` in a folder if there is one, else from fps.
  std::string times_path;
};

struct Frame {
  int64_t index = 0;  ///< 0-based position in the source
  double t_s = 0.0;   ///< time (s)
  std::string name;   ///< file name (folder) or "frame <index>" (video)
  cv::Mat bgr;        ///< CV_8UC3 image
};

class FrameSource {
 public:
  /// Opens a folder or a video. Throws InputError (see above).
  static FrameSource open(const std::string& path, const FrameSourceOptions& options = {});

  ~FrameSource();
  FrameSource(FrameSource&&) noexcept;
  FrameSource& operator=(FrameSource&&) noexcept;

  /// The next frame into `frame` (its image buffer is reused); false at the end. Throws
  /// InputError for an undecodable image, a frame of another size than the first, or a frame
  /// missing from the times file.
  bool next(Frame& frame);

  /// Number of frames: exact for a folder, the container's figure for a video (may be missing or
  /// approximate).
  std::optional<int64_t> frame_count() const;
  /// The path as opened, and "folder" or "video".
  const std::string& path() const;
  const char* kind() const;
  /// The times file in use ("" when times come from the fps), and the fps.
  const std::string& times_path() const;
  double fps() const;

 private:
  struct Impl;
  explicit FrameSource(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// The image files of a folder (extensions .png, .jpg, .jpeg, .bmp, .tif, .tiff in any case),
/// sorted by name. InputError for a missing folder or one without images.
/// Throws InputError when the folder does not exist or holds none.
std::vector<std::string> list_image_files(const std::string& folder);

/// Reads a `frame,t` times CSV: entry k is the time of frame k (s). Throws InputError naming the
/// file and line for a gap in the frame numbers, a non-finite or non-increasing time.
std::vector<double> read_frame_times(const std::string& path);

}  // namespace airtwin
