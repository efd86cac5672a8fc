#include "renders/png.h"

#include <fstream>

#include <opencv2/imgcodecs.hpp>

#include "common/errors.h"

namespace airtwin {

std::vector<unsigned char> encode_png(const cv::Mat& image) {
  // 8-bit, 1, 3 or 4 channels: what PNG stores and a camera gives.
  if (image.empty() || image.depth() != CV_8U ||
      !(image.channels() == 1 || image.channels() == 3 || image.channels() == 4)) {
    throw InputError("png: need a non-empty 8-bit image with 1, 3 or 4 channels");
  }
  std::vector<unsigned char> bytes;
  const std::vector<int> params{cv::IMWRITE_PNG_COMPRESSION, kPngCompressionLevel};
  bool ok = false;
  try {
    ok = cv::imencode(".png", image, bytes, params);
  } catch (const cv::Exception& e) {
    throw InputError(std::string("png: cannot encode the image: ") + e.what());
  }
  if (!ok) throw InputError("png: cannot encode the image");
  return bytes;
}

void write_png(const std::string& path, const cv::Mat& image) {
  const std::vector<unsigned char> bytes = encode_png(image);
  // Binary write; any failure (missing folder, full disk) names the file.
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw InputError(path + ": cannot open for writing");
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw InputError(path + ": cannot write the PNG file");
}

cv::Mat read_png(const std::string& path) {
  cv::Mat image;
  try {
    image = cv::imread(path, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw InputError(path + ": cannot read the image: " + e.what());
  }
  if (image.empty()) throw InputError(path + ": cannot read the image");
  return image;
}

}  // namespace airtwin
