// Box plots and histograms of a batch: the documented sizes, boxes where the quartiles put them,
// identical bytes for identical input, and InputError for values that cannot be drawn.

#include "plots/batch_plot.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/errors.h"
#include "tests/support/scratch_dir.h"

namespace airtwin::plots {
namespace {

std::string out_path(const std::string& name) {
  static const std::string dir = airtwin::testing::fresh_scratch_dir("batch_plot");
  return dir + "/" + name + ".png";
}

std::string bytes_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// Rows of column u whose pixel is the box frame's dark blue (BGR 110, 60, 20).
std::vector<int> frame_rows(const cv::Mat& img, int u) {
  std::vector<int> rows;
  for (int v = 0; v < img.rows; ++v) {
    const cv::Vec3b p = img.at<cv::Vec3b>(v, u);
    if (p[0] == 110 && p[1] == 60 && p[2] == 20) rows.push_back(v);
  }
  return rows;
}

TEST(BatchPlot, BoxPlotHasItsSizeAndTheBoxAtTheQuartiles) {
  // One group 0..100: quartiles 25 and 75 on a y axis from 0 to 105.
  std::vector<double> values;
  for (int k = 0; k <= 100; ++k) values.push_back(k);
  const std::string path = out_path("box");
  write_box_plot_png("t", "y", {{"a", "note", values}, {"b", "", {}}}, path);
  const cv::Mat img = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_EQ(img.cols, 640);
  ASSERT_EQ(img.rows, 560);
  // The plot area is rows 60..469 for y 105..0; the first group's box edge is 30% of its
  // 255 px wide slot left of its centre, 40 px at most.
  const double row_of_25 = 60 + (105.0 - 25.0) / 105.0 * 409.0;
  const double row_of_75 = 60 + (105.0 - 75.0) / 105.0 * 409.0;
  const int centre = 100 + static_cast<int>(std::lround(0.5 * 255.0 * 509.0 / 510.0));
  const int edge = centre - std::min(40, static_cast<int>(0.3 * 255.0));
  const std::vector<int> rows = frame_rows(img, edge);
  ASSERT_FALSE(rows.empty());
  EXPECT_NEAR(rows.front(), row_of_75, 2.0);
  EXPECT_NEAR(rows.back(), row_of_25, 2.0);
  // Same input, same bytes.
  write_box_plot_png("t", "y", {{"a", "note", values}, {"b", "", {}}}, out_path("box2"));
  EXPECT_EQ(bytes_of(path), bytes_of(out_path("box2")));
}

TEST(BatchPlot, WidthGrowsWithTheGroups) {
  std::vector<BoxGroup> groups(12, BoxGroup{"a_rather_long_scenario_name", "10/10 done", {1, 2}});
  write_box_plot_png("t", "y", groups, out_path("wide"));
  EXPECT_EQ(cv::imread(out_path("wide")).cols, 120 + 110 * 12);
}

TEST(BatchPlot, HistogramsSideBySide) {
  const std::string path = out_path("hist");
  write_histograms_png("line: 3 runs",
                       {{"completion time", "s", "", {30, 31, 35}},
                        {"error", "cm", "", {2, 2}},
                        {"none", "cm", "no runs", {}}},
                       path);
  const cv::Mat img = cv::imread(path);
  EXPECT_EQ(img.cols, 3 * 560);
  EXPECT_EQ(img.rows, 470);
}

TEST(BatchPlot, NonFiniteValuesAreInputErrors) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(write_box_plot_png("t", "y", {{"a", "", {1, nan}}}, out_path("nan")), InputError);
  EXPECT_THROW(write_histograms_png("t", {{"a", "x", "", {1, INFINITY}}}, out_path("inf")),
               InputError);
}

}  // namespace
}  // namespace airtwin::plots
