// Frame sources: a folder of images in name order with times from the fps or times.csv, a video
// decoded by FFmpeg (written here losslessly, so its frames must equal the images), and every
// error a user can cause named in one InputError.

#include "vision/frame_source.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "common/errors.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {
namespace fs = std::filesystem;

// A fresh folder under the temp dir for one test.
std::string scratch(const std::string& name) {
  const fs::path dir = fs::path(testing::scratch_root()) / "frame_source" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

// Frame k: a grey image with a white square at a place that depends on k.
cv::Mat test_frame(int k, cv::Size size = {64, 48}) {
  cv::Mat image(size, CV_8UC3, cv::Scalar(80, 85, 90));
  cv::rectangle(image, cv::Rect(4 + 5 * k, 10, 8, 8), cv::Scalar(255, 255, 255), cv::FILLED);
  return image;
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// The message of the InputError `f` throws ("" if none).
template <typename F>
std::string input_error(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(FrameSource, FolderInNameOrderWithTimesFromFps) {
  const std::string dir = scratch("fps");
  // Written out of order, with a file that is no image and a JPEG.
  cv::imwrite(dir + "/f_002.png", test_frame(2));
  cv::imwrite(dir + "/f_000.png", test_frame(0));
  cv::imwrite(dir + "/f_001.PNG", test_frame(1));
  cv::imwrite(dir + "/f_003.jpg", test_frame(3));
  write_file(dir + "/notes.txt", "not a frame");
  FrameSourceOptions options;
  options.fps = 20.0;
  FrameSource source = FrameSource::open(dir, options);
  EXPECT_STREQ(source.kind(), "folder");
  ASSERT_TRUE(source.frame_count().has_value());
  EXPECT_EQ(*source.frame_count(), 4);
  Frame frame;
  const std::vector<std::string> names = {"f_000.png", "f_001.PNG", "f_002.png", "f_003.jpg"};
  for (int k = 0; k < 4; ++k) {
    ASSERT_TRUE(source.next(frame));
    EXPECT_EQ(frame.index, k);
    EXPECT_EQ(frame.name, names[k]);
    EXPECT_DOUBLE_EQ(frame.t_s, k / 20.0);
    ASSERT_EQ(frame.bgr.type(), CV_8UC3);
    if (k < 3) {  // the PNGs are lossless
      EXPECT_EQ(cv::norm(frame.bgr, test_frame(k), cv::NORM_INF), 0.0);
    }
  }
  EXPECT_FALSE(source.next(frame));
}

TEST(FrameSource, TimesCsvInTheFolderGivesTheTimes) {
  const std::string dir = scratch("times");
  for (int k = 0; k < 3; ++k) cv::imwrite(dir + "/f" + std::to_string(k) + ".png", test_frame(k));
  write_file(dir + "/times.csv", "frame,t\n0,10.0\n1,10.03\n2,10.051\n");
  FrameSource source = FrameSource::open(dir);
  Frame frame;
  const std::vector<double> t = {10.0, 10.03, 10.051};
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(source.next(frame));
    EXPECT_DOUBLE_EQ(frame.t_s, t[k]);
  }
}

TEST(FrameSource, TimesFileErrorsNameFileAndLine) {
  const std::string dir = scratch("bad_times");
  for (int k = 0; k < 3; ++k) cv::imwrite(dir + "/f" + std::to_string(k) + ".png", test_frame(k));
  write_file(dir + "/times.csv", "frame,t\n0,0.0\n1,0.0\n");
  EXPECT_NE(input_error([&] { FrameSource::open(dir); }).find("times.csv:3"), std::string::npos);
  write_file(dir + "/times.csv", "frame,t\n0,0.0\n2,0.1\n");
  EXPECT_NE(input_error([&] { FrameSource::open(dir); }).find("expected 1"), std::string::npos);
  // Too short for the frames: the error comes with the first frame it lacks.
  write_file(dir + "/times.csv", "frame,t\n0,0.0\n1,0.1\n");
  FrameSource source = FrameSource::open(dir);
  Frame frame;
  ASSERT_TRUE(source.next(frame));
  ASSERT_TRUE(source.next(frame));
  EXPECT_NE(input_error([&] { source.next(frame); }).find("no time for frame 2"),
            std::string::npos);
}

TEST(FrameSource, LosslessVideoGivesTheSameFrames) {
  const std::string dir = scratch("video");
  const std::string path = dir + "/clip.mkv";
  {
    cv::VideoWriter writer(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 40.0,
                           cv::Size(64, 48));
    ASSERT_TRUE(writer.isOpened());
    for (int k = 0; k < 6; ++k) writer.write(test_frame(k));
  }
  FrameSource source = FrameSource::open(path);
  EXPECT_STREQ(source.kind(), "video");
  Frame frame;
  int k = 0;
  while (source.next(frame)) {
    EXPECT_EQ(frame.index, k);
    EXPECT_DOUBLE_EQ(frame.t_s, k / 40.0);
    EXPECT_EQ(frame.name, "frame " + std::to_string(k));
    EXPECT_EQ(cv::norm(frame.bgr, test_frame(k), cv::NORM_INF), 0.0) << "frame " << k;
    ++k;
  }
  EXPECT_EQ(k, 6);
}

TEST(FrameSource, UserErrorsAreInputErrorsNamingThePath) {
  const std::string dir = scratch("errors");
  // Missing path, empty folder, folder without images.
  EXPECT_NE(input_error([&] { FrameSource::open(dir + "/nothing"); }).find("no such file"),
            std::string::npos);
  EXPECT_NE(input_error([&] { FrameSource::open(dir); }).find("no image files"), std::string::npos);
  write_file(dir + "/readme.txt", "hello");
  EXPECT_NE(input_error([&] { FrameSource::open(dir); }).find(dir), std::string::npos);
  // A file that is no video.
  EXPECT_NE(input_error([&] { FrameSource::open(dir + "/readme.txt"); }).find("readme.txt"),
            std::string::npos);
  // An image that cannot be decoded, and one of another size.
  const std::string images = scratch("bad_images");
  cv::imwrite(images + "/a.png", test_frame(0));
  write_file(images + "/b.png", "this is not a PNG");
  FrameSource source = FrameSource::open(images);
  Frame frame;
  ASSERT_TRUE(source.next(frame));
  EXPECT_NE(input_error([&] { source.next(frame); }).find("b.png: cannot decode"),
            std::string::npos);
  cv::imwrite(images + "/b.png", test_frame(1, {32, 32}));
  FrameSource sizes = FrameSource::open(images);
  ASSERT_TRUE(sizes.next(frame));
  EXPECT_NE(input_error([&] { sizes.next(frame); }).find("b.png is 32 x 32 px"), std::string::npos);
  // A bad fps.
  FrameSourceOptions options;
  options.fps = 0;
  EXPECT_FALSE(input_error([&] { FrameSource::open(images, options); }).empty());
}

}  // namespace
}  // namespace airtwin
