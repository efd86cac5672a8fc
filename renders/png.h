#pragma once
// Frames as PNG files: lossless, 8-bit, and deterministic (the same image gives the same bytes:
// no timestamps or other metadata are written).

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace airtwin {

/// zlib level used for frames: 1 favours speed (a 1024 x 1024 frame in ~10-20 ms); the files
/// are ~20-40 % larger than at level 9.
inline constexpr int kPngCompressionLevel = 1;

/// PNG bytes of an 8-bit image with 1 (grey), 3 (BGR) or 4 (BGRA) channels. Throws InputError
/// for any other type or an empty image.
std::vector<unsigned char> encode_png(const cv::Mat& image);

/// Writes encode_png(image) to `path` (replacing it). Throws InputError naming the path when the
/// file cannot be written, or as encode_png does.
void write_png(const std::string& path, const cv::Mat& image);

/// Reads a PNG (or any image OpenCV reads) as stored: 8-bit BGR, grey or BGRA. Throws InputError
/// naming the path when it cannot be read.
cv::Mat read_png(const std::string& path);

}  // namespace airtwin
