// `airtwin detect` end to end: frames of a twin run written as PNGs (and as a lossless video),
// the true camera written as calib.yaml, the CSV it writes checked against the twin's object
// positions; same input, same bytes; a folder's times.csv; one clear line for every bad input.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "common/csv.h"
#include "renders/camera_model.h"
#include "renders/frame_renderer.h"
#include "sim/twin.h"
#include "tests/app/cli_runner.h"
#include "tests/vision/twin_frames.h"

namespace airtwin {
namespace {

using testing::count_lines;
using testing::run_airtwin;
using testing::scratch_dir;

struct TruthRow {
  std::string id, object;
  Eigen::Vector2d p_W;
};

// A twin run written as a dataset: DIR/frames/NNN.png, DIR/calib.yaml (the true camera), and
// the twin's object positions per frame. Five objects blown by the jet, at 40 Hz.
struct Dataset {
  std::string dir;
  std::vector<std::vector<TruthRow>> truth;  // per frame
};

Dataset make_dataset(int frames) {
  Dataset out;
  out.dir = scratch_dir("detect_dataset_" + std::to_string(frames));
  TwinParameters params;
  params.jet_on_at_start = true;
  params.initial_orientation = {2.0, 0.35};
  SceneSpec spec;
  spec.objects = {{"t1", "tracer", {-0.6, 0.3}, std::nullopt},
                  {"t2", "tracer", {-0.45, 0.5}, std::nullopt},
                  {"c1", "cotton", {-0.3, 0.3}, std::nullopt},
                  {"t3", "tracer", {0.5, -0.4}, std::nullopt},
                  {"c2", "cotton", {0.7, 0.6}, std::nullopt}};
  static const AirFieldModel field = AirFieldModel::with_constructed_table();
  Twin twin(spec, params, field, 3);
  twin.settle_jet();
  RenderOptions options;
  options.noise_sigma_grey = 3.0;
  options.blur_sigma_px = 0.7;
  options.seed = 2;
  FrameRenderer renderer(twin.model(), options);
  testing::camera_from_truth(GroundTruthCamera::from_model(twin.model()))
      .write(out.dir + "/calib.yaml");
  std::filesystem::create_directories(out.dir + "/frames");
  for (int f = 0; f < frames; ++f) {
    char name[64];
    std::snprintf(name, sizeof name, "/frames/%03d.png", f);
    cv::imwrite(out.dir + name, renderer.render(twin.data(), f), {cv::IMWRITE_PNG_COMPRESSION, 1});
    std::vector<TruthRow> rows;
    for (size_t i = 0; i < twin.object_count(); ++i) {
      rows.push_back(
          {twin.object(i).id, object_type_name(twin.object(i).type), twin.object_state(i).p_W});
    }
    out.truth.push_back(rows);
    twin.advance(1.0 / 40.0);
  }
  return out;
}

// The dataset of `frames` frames, made once per process.
const Dataset& dataset(int frames) {
  static std::map<int, Dataset> made;
  if (!made.count(frames)) made[frames] = make_dataset(frames);
  return made[frames];
}

void expect_error(const std::string& args, int code, const std::string& fragment) {
  const auto r = run_airtwin(args);
  EXPECT_EQ(r.exit_code, code) << args << "\nstderr: " << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << args << "\nstderr: " << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << args << "\nstderr: " << r.err;
}

TEST(DetectCli, WritesDetectionsMatchingTheTwin) {
  const Dataset& d = dataset(40);  // 40 frames: enough for the progress lines
  const std::string out = scratch_dir("detect_out");
  const std::string args = "detect " + d.dir + "/frames --calib " + d.dir + "/calib.yaml";
  const auto r = run_airtwin(args + " --out " + out + "/a/detections.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("detect: 40 frames (folder, 40 Hz from --fps), 200 detections, 5 tracks"),
            std::string::npos)
      << r.out;
  // Progress on stderr as plain lines (not a terminal), the last at 40/40.
  EXPECT_NE(r.err.find("detect 40/40 frames"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos);

  const std::string text = read_text_file(out + "/a/detections.csv");
  EXPECT_EQ(text.substr(0, text.find('\n')), "frame,t,id,object,x,y,x_px,y_px");
  const CsvTable table = CsvTable::parse(text, "detections.csv",
                                         {"frame", "t", "id", "object", "x", "y", "x_px", "y_px"});
  ASSERT_EQ(table.rows(), 200u);
  // Six decimals in every number but the frame and the id.
  EXPECT_EQ(table.text(0, "t"), "0.000000");
  EXPECT_EQ(table.text(0, "x").size() - table.text(0, "x").find('.'), 7u);
  // Each row against the twin: the nearest object within 3 mm, its kind; one id per object.
  std::map<std::string, std::string> id_of;
  double worst = 0.0;
  for (size_t row = 0; row < table.rows(); ++row) {
    const int f = static_cast<int>(table.number(row, "frame"));
    EXPECT_DOUBLE_EQ(table.number(row, "t"), f / 40.0);
    const Eigen::Vector2d p(table.number(row, "x"), table.number(row, "y"));
    const TruthRow* best = nullptr;
    for (const TruthRow& t : d.truth[f]) {
      if (!best || (t.p_W - p).norm() < (best->p_W - p).norm()) best = &t;
    }
    worst = std::max(worst, (best->p_W - p).norm());
    EXPECT_EQ(table.text(row, "object"), best->object) << table.where(row);
    if (!id_of.count(best->id)) id_of[best->id] = table.text(row, "id");
    EXPECT_EQ(table.text(row, "id"), id_of[best->id]) << table.where(row);
  }
  EXPECT_EQ(id_of.size(), 5u);
  EXPECT_LT(worst, 0.003);

  // Same input, same bytes; --quiet silences the progress.
  const auto again = run_airtwin(args + " --quiet --out " + out + "/b.csv");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_TRUE(again.err.empty()) << again.err;
  EXPECT_EQ(read_text_file(out + "/b.csv"), text);
}

TEST(DetectCli, LosslessVideoGivesTheSameCsv) {
  // 12 frames as a folder and as an FFV1 video (lossless): the same CSV.
  const Dataset& d = dataset(12);
  const std::string out = scratch_dir("detect_video");
  std::filesystem::create_directories(out + "/frames");
  {
    cv::VideoWriter writer(out + "/clip.mkv", cv::CAP_FFMPEG,
                           cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 40.0, cv::Size(1024, 1024));
    ASSERT_TRUE(writer.isOpened());
    for (int f = 0; f < 12; ++f) {
      char name[64];
      std::snprintf(name, sizeof name, "/frames/%03d.png", f);
      std::filesystem::copy_file(d.dir + name, out + name);
      writer.write(cv::imread(d.dir + name));
    }
  }
  const std::string calib = " --calib " + d.dir + "/calib.yaml --quiet";
  ASSERT_EQ(run_airtwin("detect " + out + "/clip.mkv --out " + out + "/v.csv" + calib).exit_code,
            0);
  ASSERT_EQ(run_airtwin("detect " + out + "/frames --out " + out + "/f.csv" + calib).exit_code, 0);
  EXPECT_EQ(read_text_file(out + "/v.csv"), read_text_file(out + "/f.csv"));
  EXPECT_EQ(count_lines(read_text_file(out + "/v.csv")), 1 + 12 * 5);
  // --fps sets the times.
  const auto r =
      run_airtwin("detect " + out + "/clip.mkv --fps 20 --out " + out + "/s.csv" + calib);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CsvTable table =
      CsvTable::read_file(out + "/s.csv", {"frame", "t", "id", "object", "x", "y", "x_px", "y_px"});
  EXPECT_EQ(table.text(table.rows() - 1, "t"), "0.550000");
}

TEST(DetectCli, TimesCsvInTheFolder) {
  const std::string dir = scratch_dir("detect_times");
  const Dataset& d = dataset(3);
  std::filesystem::create_directories(dir + "/frames");
  std::string times = "frame,t\n";
  for (int f = 0; f < 3; ++f) {
    char name[64];
    std::snprintf(name, sizeof name, "/frames/%03d.png", f);
    std::filesystem::copy_file(d.dir + name, dir + name);
    times += std::to_string(f) + "," + std::to_string(100.0 + 0.03 * f) + "\n";
  }
  std::ofstream(dir + "/frames/times.csv") << times;
  const auto r = run_airtwin("detect " + dir + "/frames --calib " + d.dir + "/calib.yaml --out " +
                             dir + "/d.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("times from"), std::string::npos) << r.out;
  const CsvTable table =
      CsvTable::read_file(dir + "/d.csv", {"frame", "t", "id", "object", "x", "y", "x_px", "y_px"});
  EXPECT_EQ(table.text(table.rows() - 1, "t"), "100.060000");
}

TEST(DetectCli, BadInputIsOneClearLine) {
  const Dataset& d = dataset(2);
  const std::string dir = scratch_dir("detect_errors");
  const std::string calib = " --calib " + d.dir + "/calib.yaml";
  const std::string out = " --out " + dir + "/x.csv";
  // Usage errors: exit 2.
  expect_error("detect " + d.dir + "/frames" + calib, 2, "--out");
  expect_error("detect " + d.dir + "/frames --out x.csv", 2, "--calib");
  expect_error("detect " + d.dir + "/frames" + calib + out + " --fps 0", 2, "--fps");
  expect_error("detect " + d.dir + "/frames" + calib + out + " --max-jump -1", 2, "--max-jump");
  // Bad input: exit 1, naming the culprit.
  expect_error("detect " + dir + "/none" + calib + out, 1, "none: no such file or folder");
  std::filesystem::create_directories(dir + "/empty");
  expect_error("detect " + dir + "/empty" + calib + out, 1, "no image files");
  std::ofstream(dir + "/bad.mp4") << "not a video";
  expect_error("detect " + dir + "/bad.mp4" + calib + out, 1, "bad.mp4: cannot open as a video");
  expect_error("detect " + d.dir + "/frames --calib " + dir + "/none.yaml" + out, 1, "none.yaml");
  std::ofstream(dir + "/broken.yaml") << "%YAML:1.0\nwidth_px: 1024\n";
  expect_error("detect " + d.dir + "/frames --calib " + dir + "/broken.yaml" + out, 1,
               "broken.yaml");
  std::filesystem::create_directories(dir + "/small");
  cv::imwrite(dir + "/small/000.png", cv::Mat(100, 120, CV_8UC3, cv::Scalar(80, 80, 80)));
  expect_error("detect " + dir + "/small" + calib + out, 1, "000.png is 120 x 100 px");
  std::filesystem::create_directories(dir + "/garbage");
  std::ofstream(dir + "/garbage/000.png") << "not a png";
  expect_error("detect " + dir + "/garbage" + calib + out, 1, "000.png: cannot decode");
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.csv"));  // nothing written on failure
}

}  // namespace
}  // namespace airtwin
