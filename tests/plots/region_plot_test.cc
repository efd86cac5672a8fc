// The region picture: its documented size and map, a green arrow where a push moved and none where
// it did not, identical bytes for identical input, and InputError naming the file for input that
// cannot be drawn.

#include "plots/region_plot.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/errors.h"
#include "tests/support/scratch_dir.h"

namespace airtwin::plots {
namespace {

std::string out_path(const std::string& name) {
  static const std::string dir = airtwin::testing::fresh_scratch_dir("region_plot");
  return dir + "/" + name + ".png";
}

std::string bytes_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

bool green(const cv::Vec3b& p) { return p[0] == 60 && p[1] == 160 && p[2] == 40; }

// Green pixels in columns [u0, u1) of the map rows.
int green_in(const cv::Mat& img, int u0, int u1) {
  int n = 0;
  for (int v = 60; v < 560; ++v) {
    for (int u = u0; u < u1; ++u) n += green(img.at<cv::Vec3b>(v, u)) ? 1 : 0;
  }
  return n;
}

// Two points (0.4, 0) and (-0.4, 0), the +x push only; on [-0.6, 0.6] both axes.
RegionPlot two_points(PushVerdict left, PushVerdict right) {
  RegionPlot plot;
  plot.extent_m = 0.4;
  plot.step_m = 0.4;
  plot.points_W = {{0.4, 0.0}, {-0.4, 0.0}};
  plot.directions_W = {{1.0, 0.0}, {1.0, 0.0}};
  plot.panels = {{"model", {left, left}}, {"twin", {right, PushVerdict::kUnreachable}}};
  plot.caption = {"caption", "second line"};
  return plot;
}

TEST(RegionPlot, MovedPushesAreGreenArrowsWhereThePointIs) {
  const std::string path = out_path("two");
  write_region_png(two_points(PushVerdict::kMoved, PushVerdict::kStill), path);
  const cv::Mat img = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_EQ(img.cols, 1240);
  ASSERT_EQ(img.rows, 720);
  // The left map: the arrow of (0.4, 0) runs from x 0.432 to 0.568 m on row y 0, i.e. columns
  // 80 + (x + 0.6) / 1.2 * 499 = 526.3 .. 582.9 (the map ends at 579), row 309.5.
  const auto column = [](double x) { return static_cast<int>(80 + (x + 0.6) / 1.2 * 499.0); };
  EXPECT_GT(green_in(img, column(0.45), column(0.55)), 20);
  EXPECT_GT(green_in(img, column(-0.35), column(-0.25)), 20);  // (-0.4, 0)'s arrow
  EXPECT_EQ(green_in(img, column(-0.2), column(0.4)), 0);      // nothing between them
  // The right map: a still push and an unreachable one, no green at all.
  EXPECT_EQ(green_in(img, 620, 1240), 0);
  // The same input, the same bytes; another verdict, other bytes.
  const std::string again = out_path("two_again");
  write_region_png(two_points(PushVerdict::kMoved, PushVerdict::kStill), again);
  EXPECT_EQ(bytes_of(path), bytes_of(again));
  write_region_png(two_points(PushVerdict::kMoved, PushVerdict::kMoved), again);
  EXPECT_NE(bytes_of(path), bytes_of(again));
  EXPECT_GT(green_in(cv::imread(again, cv::IMREAD_COLOR), 620, 1240), 20);
}

TEST(RegionPlot, OnePanelIsHalfAsWide) {
  RegionPlot plot = two_points(PushVerdict::kMoved, PushVerdict::kStill);
  plot.panels.pop_back();
  const std::string path = out_path("one");
  write_region_png(plot, path);
  EXPECT_EQ(cv::imread(path, cv::IMREAD_COLOR).cols, 620);
}

// A scenario's task is drawn in blue over every map: a path, a zone, an object.
TEST(RegionPlot, TheTaskIsDrawnOverEveryMap) {
  RegionPlot plot = two_points(PushVerdict::kStill, PushVerdict::kStill);
  const std::string plain = out_path("plain");
  write_region_png(plot, plain);
  plot.path_W = {{-0.5, 0.5}, {0.5, 0.5}};
  plot.zones = {{{0.0, -0.3}, 0.1}};
  plot.objects_W = {{-0.5, -0.5}};
  const std::string task = out_path("task");
  write_region_png(plot, task);
  const auto blue = [](const cv::Mat& img, int u0, int u1) {
    int n = 0;
    for (int v = 60; v < 560; ++v) {
      for (int u = u0; u < u1; ++u) {
        const cv::Vec3b p = img.at<cv::Vec3b>(v, u);
        n += (p[0] == 200 && p[1] == 110 && p[2] == 30) ? 1 : 0;
      }
    }
    return n;
  };
  const cv::Mat a = cv::imread(plain, cv::IMREAD_COLOR), b = cv::imread(task, cv::IMREAD_COLOR);
  EXPECT_EQ(blue(a, 0, 1240), 0);
  EXPECT_GT(blue(b, 0, 620), 200);     // the left map
  EXPECT_GT(blue(b, 620, 1240), 200);  // and the right one
  // The path's row: y 0.5 m is row 60 + (0.6 - 0.5) / 1.2 * 499 = 101.6.
  EXPECT_TRUE(b.at<cv::Vec3b>(102, 330) == cv::Vec3b(200, 110, 30) ||
              b.at<cv::Vec3b>(101, 330) == cv::Vec3b(200, 110, 30));
  plot.zones = {{{0.0, 0.0}, 0.0}};
  EXPECT_THROW(write_region_png(plot, task), InputError);
}

TEST(RegionPlot, InputThatCannotBeDrawnIsAnErrorNamingTheFile) {
  const std::string path = out_path("bad");
  const auto message = [&](const RegionPlot& plot) {
    try {
      write_region_png(plot, path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  RegionPlot plot = two_points(PushVerdict::kMoved, PushVerdict::kStill);
  plot.panels[1].verdicts.pop_back();
  EXPECT_NE(message(plot).find(path + ": region picture: panel 'twin' has 1 verdicts for 2"),
            std::string::npos)
      << message(plot);
  plot = two_points(PushVerdict::kMoved, PushVerdict::kStill);
  plot.directions_W.pop_back();
  EXPECT_NE(message(plot).find("2 points but 1 directions"), std::string::npos);
  plot = two_points(PushVerdict::kMoved, PushVerdict::kStill);
  plot.panels.clear();
  EXPECT_NE(message(plot).find("expected 1 or 2 panels, got 0"), std::string::npos);
  plot = two_points(PushVerdict::kMoved, PushVerdict::kStill);
  plot.points_W[0].x() = std::nan("");
  EXPECT_NE(message(plot).find("push 0 is not finite"), std::string::npos);
  plot = two_points(PushVerdict::kMoved, PushVerdict::kStill);
  plot.step_m = 0.0;
  EXPECT_NE(message(plot).find("step_m is not > 0"), std::string::npos);
}

}  // namespace
}  // namespace airtwin::plots
