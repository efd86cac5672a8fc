// PNG frames: lossless, deterministic bytes, clear errors.

#include "renders/png.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "common/errors.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

cv::Mat pattern() {
  cv::Mat image(48, 64, CV_8UC3);
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) {
      image.at<cv::Vec3b>(r, c) = cv::Vec3b(r * 5, c * 4, (r * c) % 256);
    }
  }
  return image;
}

TEST(Png, RoundTripIsLosslessAndBytesRepeat) {
  const cv::Mat image = pattern();
  const auto bytes = encode_png(image);
  EXPECT_EQ(bytes, encode_png(image.clone()));
  const std::filesystem::path path =
      std::filesystem::path(testing::scratch_root()) / "png_test_frame.png";
  write_png(path.string(), image);
  std::ifstream in(path, std::ios::binary);
  const std::vector<unsigned char> on_disk((std::istreambuf_iterator<char>(in)), {});
  EXPECT_EQ(on_disk, bytes);
  const cv::Mat back = read_png(path.string());
  ASSERT_EQ(back.type(), CV_8UC3);
  ASSERT_EQ(back.size(), image.size());
  EXPECT_EQ(std::memcmp(back.data, image.data, image.total() * image.elemSize()), 0);
  std::filesystem::remove(path);
}

TEST(Png, ErrorsNameTheFile) {
  try {
    write_png("/nonexistent-dir/frame.png", pattern());
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/frame.png"), std::string::npos);
  }
  EXPECT_THROW(read_png("/nonexistent-dir/frame.png"), InputError);
  EXPECT_THROW(encode_png(cv::Mat()), InputError);
  EXPECT_THROW(encode_png(cv::Mat(4, 4, CV_32FC1)), InputError);
}

}  // namespace
}  // namespace airtwin
