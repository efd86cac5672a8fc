// The H.264 video writer: what is written is read back by an independent decoder path
// (cv::VideoCapture) with the right frame count, size and content; the stride keeps every k-th
// frame and says so in the sidecar; a slow encoder behind a one-frame queue loses nothing; bad
// paths, sizes and options are one clear InputError.

#include "renders/video_writer.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "common/errors.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

std::string scratch(const std::string& name) {
  const auto dir = std::filesystem::path(testing::scratch_root()) / ("video_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

// A frame like the camera's: a grey floor with a soft checker, white discs that move with k.
cv::Mat synthetic_frame(int k) {
  cv::Mat frame(1024, 1024, CV_8UC3, cv::Scalar(86, 91, 99));
  for (int r = 0; r < 1024; r += 190) {
    for (int c = (r / 190) % 2 * 190; c < 1024; c += 380) {
      cv::rectangle(frame, cv::Rect(c, r, 190, 190), cv::Scalar(76, 81, 89), cv::FILLED);
    }
  }
  for (int j = 0; j < 5; ++j) {
    const cv::Point centre(150 + 150 * j + 6 * k, 300 + 90 * j - 4 * k);
    cv::circle(frame, centre, 6 + 2 * j, cv::Scalar(245, 245, 245), cv::FILLED, cv::LINE_AA);
  }
  return frame;
}

double mean_abs_diff(const cv::Mat& a, const cv::Mat& b) {
  return cv::norm(a, b, cv::NORM_L1) / static_cast<double>(a.total() * a.channels());
}

std::vector<cv::Mat> read_back(const std::string& path) {
  cv::VideoCapture capture(path, cv::CAP_FFMPEG);
  EXPECT_TRUE(capture.isOpened()) << path;
  std::vector<cv::Mat> frames;
  cv::Mat frame;
  while (capture.read(frame)) frames.push_back(frame.clone());
  return frames;
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  return nlohmann::json::parse(in);
}

TEST(VideoWriter, WhatIsWrittenReadsBackCloseToTheFrames) {
  const std::string path = scratch("plain") + "/run.mp4";
  std::vector<cv::Mat> frames;
  for (int k = 0; k < 20; ++k) frames.push_back(synthetic_frame(k));
  VideoWriter writer(path);
  for (const cv::Mat& f : frames) EXPECT_TRUE(writer.write(f));
  const VideoSummary s = writer.close();
  EXPECT_EQ(s.frames_offered, 20);
  EXPECT_EQ(s.frames_written, 20);
  EXPECT_DOUBLE_EQ(s.sim_seconds, 0.5);  // 20 frames at 40 Hz
  EXPECT_DOUBLE_EQ(s.video_seconds, 0.5);
  EXPECT_DOUBLE_EQ(s.time_scale, 1.0);
  EXPECT_GT(s.encode_ms_per_frame, 0.0);

  cv::VideoCapture capture(path, cv::CAP_FFMPEG);
  ASSERT_TRUE(capture.isOpened());
  EXPECT_EQ(capture.get(cv::CAP_PROP_FRAME_COUNT), 20);
  EXPECT_NEAR(capture.get(cv::CAP_PROP_FPS), 40.0, 1e-6);
  capture.release();
  const std::vector<cv::Mat> back = read_back(path);
  ASSERT_EQ(back.size(), 20u);
  for (int k = 0; k < 20; ++k) {
    ASSERT_EQ(back[k].size(), cv::Size(1024, 1024));
    ASSERT_EQ(back[k].type(), CV_8UC3);
    // Lossy, but close: within a few grey levels on average (~3, mostly the BGR -> YUV 4:2:0
    // limited-range round trip, which darkens the floor by 1-4 levels), and frame k is nearer to
    // its own source than to the next one (the order is kept).
    const double own = mean_abs_diff(back[k], frames[k]);
    EXPECT_LT(own, 4.0) << "frame " << k;
    if (k + 1 < 20) {
      EXPECT_LT(own, mean_abs_diff(back[k], frames[k + 1])) << "frame " << k;
    }
  }

  const nlohmann::json j = read_json(path + ".json");
  EXPECT_EQ(j.at("fps").get<double>(), 40.0);
  EXPECT_EQ(j.at("stride").get<int>(), 1);
  EXPECT_EQ(j.at("frames").get<int>(), 20);
  EXPECT_DOUBLE_EQ(j.at("sim_seconds").get<double>(), 0.5);
  EXPECT_EQ(j.at("codec").get<std::string>(), "avc1");
  // close() again: the same summary, no second encoding.
  EXPECT_EQ(writer.close().frames_written, 20);
}

TEST(VideoWriter, StrideKeepsEveryKthFrameAndReportsTheTimeScale) {
  const std::string path = scratch("stride") + "/fast.mp4";
  VideoOptions o;
  o.stride = 3;
  o.queue_capacity = 1;  // the producer waits on the encoder nearly every frame: nothing is lost
  std::vector<cv::Mat> frames;
  VideoWriter writer(path, o);
  for (int k = 0; k < 10; ++k) {
    frames.push_back(synthetic_frame(3 * k));
    EXPECT_EQ(writer.write(frames.back()), k % 3 == 0) << k;
  }
  const VideoSummary s = writer.close();
  EXPECT_EQ(s.frames_offered, 10);
  EXPECT_EQ(s.frames_written, 4);  // 0, 3, 6, 9
  EXPECT_DOUBLE_EQ(s.time_scale, 3.0);
  EXPECT_DOUBLE_EQ(s.sim_seconds, 0.25);
  // Frames offered at 20 Hz of simulated time, played at 40 fps: 2 simulated s per video s.
  VideoOptions slow;
  slow.camera_rate_hz = 20.0;
  EXPECT_DOUBLE_EQ(slow.time_scale(), 2.0);
  const std::vector<cv::Mat> back = read_back(path);
  ASSERT_EQ(back.size(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_LT(mean_abs_diff(back[i], frames[3 * i]), 4.0) << i;
  const nlohmann::json j = read_json(path + ".json");
  EXPECT_EQ(j.at("stride").get<int>(), 3);
  EXPECT_EQ(j.at("frames").get<int>(), 4);
  EXPECT_EQ(j.at("frames_offered").get<int>(), 10);
  EXPECT_DOUBLE_EQ(j.at("time_scale").get<double>(), 3.0);
}

TEST(VideoWriter, ErrorsNameTheFileAndTheProblem) {
  // A folder that does not exist.
  try {
    VideoWriter writer("/nonexistent/folder/v.mp4");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/folder/v.mp4"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
  // A frame of the wrong size or type.
  const std::string path = scratch("errors") + "/v.mp4";
  {
    VideoWriter writer(path);
    writer.write(synthetic_frame(0));
    try {
      writer.write(cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(0)));
      FAIL() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("frame 1 is 640 x 480 px"), std::string::npos)
          << e.what();
    }
    EXPECT_THROW(writer.write(cv::Mat(1024, 1024, CV_8UC1, cv::Scalar(0))), InputError);
    EXPECT_EQ(writer.close().frames_written, 1);
    EXPECT_THROW(writer.write(synthetic_frame(1)), std::logic_error);
  }
  // Options out of range.
  VideoOptions o;
  o.stride = 0;
  EXPECT_THROW(VideoWriter(path, o), InputError);
  o = VideoOptions{};
  o.width_px = 1023;  // H.264 4:2:0 needs even sides
  EXPECT_THROW(o.validate(), InputError);
  o = VideoOptions{};
  o.fps = 0.0;
  EXPECT_THROW(o.validate(), InputError);
}

}  // namespace
}  // namespace airtwin
