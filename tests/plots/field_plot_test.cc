// The field picture (Fig. 3 style): written PNGs are read back and checked against independent
// truths: the documented size and map area, viridis of the known normalised speed at a pixel, the
// s and c marks at the pixels the axis mapping predicts (y up), arrows along the air direction,
// identical bytes on two writes, and InputError for malformed grids and unwritable paths.

#include "plots/field_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "common/errors.h"
#include "tests/support/scratch_dir.h"

namespace airtwin::plots {
namespace {

namespace fs = std::filesystem;

// A per-test output path (tests may run in parallel).
std::string out_path(const std::string& name) {
  const fs::path dir = fs::path(testing::scratch_root()) / "field_plot";
  fs::create_directories(dir);
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return (dir / (std::string(info->name()) + "_" + name + ".png")).string();
}

// A square grid on [-1, 1]^2 with n nodes per axis; values from functions of (x, y).
VectorFieldGrid make_grid(int n, const std::function<double(double, double)>& speed,
                          const std::function<double(double, double)>& vx,
                          const std::function<double(double, double)>& vy) {
  VectorFieldGrid g;
  g.x = Eigen::VectorXd::LinSpaced(n, -1.0, 1.0);
  g.y = g.x;
  g.vx.resize(n, n);
  g.vy.resize(n, n);
  g.speed.resize(n, n);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      g.vx(j, i) = vx(g.x[i], g.y[j]);
      g.vy(j, i) = vy(g.x[i], g.y[j]);
      g.speed(j, i) = speed(g.x[i], g.y[j]);
    }
  }
  return g;
}

double zero(double, double) { return 0.0; }

// Speed = distance from p0, no velocity (so no arrows cover the colours).
const Eigen::Vector2d kP0(0.4, 0.3);
VectorFieldGrid distance_grid() {
  return make_grid(
      41, [](double x, double y) { return std::hypot(x - kP0.x(), y - kP0.y()); }, zero, zero);
}

// The axis mapping documented in field_plot.h: pixel (column, row) of data point p.
cv::Point2d predicted_px(const VectorFieldGrid& g, const FieldPlotArea& a,
                         const Eigen::Vector2d& p) {
  const double x0 = g.x[0], x1 = g.x[g.x.size() - 1], y0 = g.y[0], y1 = g.y[g.y.size() - 1];
  return {a.left_px + (p.x() - x0) / (x1 - x0) * (a.width_px - 1),
          a.top_px + (y1 - p.y()) / (y1 - y0) * (a.height_px - 1)};
}

// Data point at the centre of pixel (u, v).
Eigen::Vector2d data_at(const VectorFieldGrid& g, const FieldPlotArea& a, int u, int v) {
  const double x0 = g.x[0], x1 = g.x[g.x.size() - 1], y0 = g.y[0], y1 = g.y[g.y.size() - 1];
  return {x0 + (u - a.left_px) * (x1 - x0) / (a.width_px - 1),
          y1 - (v - a.top_px) * (y1 - y0) / (a.height_px - 1)};
}

cv::Vec3b viridis(int index) {
  cv::Mat one(1, 1, CV_8UC1, cv::Scalar(index)), colour;
  cv::applyColorMap(one, colour, cv::COLORMAP_VIRIDIS);
  return colour.at<cv::Vec3b>(0, 0);
}

int max_channel_difference(cv::Vec3b a, cv::Vec3b b) {
  int d = 0;
  for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(int{a[k]} - int{b[k]}));
  return d;
}

double luma(cv::Vec3b bgr) { return 0.114 * bgr[0] + 0.587 * bgr[1] + 0.299 * bgr[2]; }

// Centroid (column, row) of the pixels inside `area` that satisfy `pick`; count in `n`.
cv::Point2d centroid(const cv::Mat& img, const FieldPlotArea& a,
                     const std::function<bool(cv::Vec3b)>& pick, int& n) {
  double su = 0, sv = 0;
  n = 0;
  for (int v = a.top_px; v < a.top_px + a.height_px; ++v) {
    for (int u = a.left_px; u < a.left_px + a.width_px; ++u) {
      if (pick(img.at<cv::Vec3b>(v, u))) {
        su += u;
        sv += v;
        ++n;
      }
    }
  }
  return n > 0 ? cv::Point2d(su / n, sv / n) : cv::Point2d(-1, -1);
}

bool is_red(cv::Vec3b c) { return c[2] > 180 && c[1] < 100 && c[0] < 100; }
bool is_magenta(cv::Vec3b c) { return c[2] > 180 && c[0] > 180 && c[1] < 110; }

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The InputError message of writing `grid`, or "" when nothing was thrown.
std::string error_of(const VectorFieldGrid& grid, const FieldMarks& marks,
                     const std::string& path) {
  try {
    write_field_png(grid, marks, path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(FieldPlot, WritesThePictureOfTheDocumentedSizeWithTheMapWhereDocumented) {
  const VectorFieldGrid g = distance_grid();
  const std::string path = out_path("size");
  write_field_png(g, FieldMarks{}, path);
  const cv::Mat img = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.cols, kFieldPngWidth_px);
  EXPECT_EQ(img.rows, kFieldPngHeight_px);
  EXPECT_EQ(img.type(), CV_8UC3);

  // The map is square for a square grid, inside the picture, framed by a dark line just outside.
  const FieldPlotArea a = field_plot_area(g);
  EXPECT_EQ(a.width_px, a.height_px);
  EXPECT_GT(a.width_px, 500);
  ASSERT_GE(a.left_px, 1);
  ASSERT_GE(a.top_px, 1);
  ASSERT_LT(a.left_px + a.width_px, img.cols);
  ASSERT_LT(a.top_px + a.height_px, img.rows);
  const int mid_v = a.top_px + a.height_px / 2, mid_u = a.left_px + a.width_px / 2;
  EXPECT_LT(luma(img.at<cv::Vec3b>(mid_v, a.left_px - 1)), 40);
  EXPECT_LT(luma(img.at<cv::Vec3b>(mid_v, a.left_px + a.width_px)), 40);
  EXPECT_LT(luma(img.at<cv::Vec3b>(a.top_px - 1, mid_u)), 40);
  EXPECT_LT(luma(img.at<cv::Vec3b>(a.top_px + a.height_px, mid_u)), 40);
  // White margins at the corners.
  EXPECT_EQ(img.at<cv::Vec3b>(2, 2), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(img.at<cv::Vec3b>(img.rows - 3, img.cols - 3), cv::Vec3b(255, 255, 255));
}

TEST(FieldPlot, ColourIsViridisOfTheNormalisedSpeed) {
  const VectorFieldGrid g = distance_grid();
  FieldMarks marks;
  marks.stagnation_W = {-0.6, 0.7};
  marks.projection_W = {0.7, -0.6};
  const std::string path = out_path("colour");
  write_field_png(g, marks, path);
  const cv::Mat img = cv::imread(path);
  ASSERT_FALSE(img.empty());
  const FieldPlotArea a = field_plot_area(g);

  // Documented colour range: [min(0, slowest), fastest] = [0, largest distance to a node].
  const double top = g.speed.maxCoeff();
  auto check = [&](const Eigen::Vector2d& p) {
    const cv::Point2d px = predicted_px(g, a, p);
    const int u = static_cast<int>(std::lround(px.x)), v = static_cast<int>(std::lround(px.y));
    const double speed = (data_at(g, a, u, v) - kP0).norm();
    const cv::Vec3b expected = viridis(static_cast<int>(std::lround(255 * speed / top)));
    const cv::Vec3b got = img.at<cv::Vec3b>(v, u);
    EXPECT_LE(max_channel_difference(got, expected), 8)
        << "at (" << p.x() << ", " << p.y() << ") m, pixel (" << u << ", " << v << "): got " << got
        << ", expected " << expected;
    return got;
  };
  const cv::Vec3b slow = check({0.5, 0.3});
  const cv::Vec3b middle = check({-0.2, -0.1});
  const cv::Vec3b fast = check({-0.9, -0.9});
  check({0.9, 0.9});
  check({-0.95, 0.6});

  // Viridis runs from dark purple to bright yellow: brightness grows with speed.
  EXPECT_GT(luma(middle), luma(slow) + 40);
  EXPECT_GT(luma(fast), luma(middle) + 40);
  EXPECT_GT(fast[2], 180);  // yellow: red and green high, blue low
  EXPECT_LT(fast[0], 100);
  EXPECT_GT(slow[0], slow[1]);  // purple: more blue than green
}

TEST(FieldPlot, MarksSAndCAtThePixelsTheAxisMappingPredicts) {
  const VectorFieldGrid g = distance_grid();
  FieldMarks marks;
  marks.stagnation_W = {0.3, 0.5};
  marks.projection_W = {-0.6, -0.4};
  const std::string path = out_path("marks");
  write_field_png(g, marks, path);
  const cv::Mat img = cv::imread(path);
  ASSERT_FALSE(img.empty());
  const FieldPlotArea a = field_plot_area(g);

  // s: a red disc centred where the mapping puts s (y up: above the middle row).
  const cv::Point2d s_px = predicted_px(g, a, marks.stagnation_W);
  int n_red = 0;
  const cv::Point2d red = centroid(img, a, is_red, n_red);
  EXPECT_GT(n_red, 50);
  EXPECT_NEAR(red.x, s_px.x, 1.0);
  EXPECT_NEAR(red.y, s_px.y, 1.0);
  EXPECT_LT(red.y, a.top_px + 0.5 * a.height_px);
  EXPECT_TRUE(is_red(img.at<cv::Vec3b>(static_cast<int>(std::lround(s_px.y)),
                                       static_cast<int>(std::lround(s_px.x)))));

  // c: a magenta cross centred on c's pixel.
  const cv::Point2d c_px = predicted_px(g, a, marks.projection_W);
  int n_magenta = 0;
  const cv::Point2d magenta = centroid(img, a, is_magenta, n_magenta);
  EXPECT_GT(n_magenta, 30);
  EXPECT_NEAR(magenta.x, c_px.x, 1.0);
  EXPECT_NEAR(magenta.y, c_px.y, 1.0);
}

TEST(FieldPlot, MarksOutsideTheMapArePointedAtFromTheEdge) {
  const VectorFieldGrid g = distance_grid();
  FieldMarks marks;
  marks.stagnation_W = {0.0, 1.2};  // above the map, like tilt 45 deg
  marks.projection_W = {0.0, 1.43};
  const std::string path = out_path("off_map");
  write_field_png(g, marks, path);
  const cv::Mat img = cv::imread(path);
  ASSERT_FALSE(img.empty());
  const FieldPlotArea a = field_plot_area(g);

  // A red pointer near the top edge above x = 0, and a magenta one beside it.
  int n_red = 0, n_magenta = 0;
  const cv::Point2d red = centroid(img, a, is_red, n_red);
  const cv::Point2d magenta = centroid(img, a, is_magenta, n_magenta);
  EXPECT_GT(n_red, 30);
  EXPECT_GT(n_magenta, 30);
  EXPECT_LT(red.y, a.top_px + 40);
  EXPECT_NEAR(red.x, predicted_px(g, a, {0.0, 0.0}).x, 3.0);
  EXPECT_LT(magenta.y, a.top_px + 40);
  EXPECT_GT(std::hypot(magenta.x - red.x, magenta.y - red.y), 20);  // not on top of each other

  // Far away (the model's s at high tilt) works too.
  marks.stagnation_W = {-4.3e3, -2.5e3};
  marks.projection_W = {1e200, -1e200};
  EXPECT_NO_THROW(write_field_png(g, marks, out_path("far")));
}

// White arrow pixels in the map, minus a margin that keeps the marks' labels out.
cv::Mat arrow_mask(const cv::Mat& img, const FieldPlotArea& a, int margin) {
  const cv::Rect inner(a.left_px + margin, a.top_px + margin, a.width_px - 2 * margin,
                       a.height_px - 2 * margin);
  cv::Mat mask;
  cv::inRange(img(inner), cv::Scalar(235, 235, 235), cv::Scalar(255, 255, 255), mask);
  return mask;
}

// For each run of non-empty entries of a profile (one arrow's extent along the flow): +1 when the
// far third holds more mass than the near third (the head is at the far end), -1 when less.
std::vector<int> head_sides(const std::vector<int>& profile) {
  std::vector<int> sides;
  size_t i = 0;
  while (i < profile.size()) {
    if (profile[i] == 0) {
      ++i;
      continue;
    }
    size_t j = i;
    while (j < profile.size() && profile[j] > 0) ++j;
    const size_t len = j - i;
    if (len >= 12) {
      int near = 0, far = 0;
      for (size_t k = 0; k < len / 3; ++k) {
        near += profile[i + k];
        far += profile[j - 1 - k];
      }
      sides.push_back(far > near ? 1 : -1);
    }
    i = j;
  }
  return sides;
}

TEST(FieldPlot, ArrowsPointAlongTheAirDirection) {
  FieldMarks marks;
  marks.stagnation_W = {-5.0, 0.0};  // off the map, left; their pointers stay in the margin
  marks.projection_W = {-5.0, 0.3};
  auto one = [](double, double) { return 1.0; };
  auto minus_one = [](double, double) { return -1.0; };
  const int margin = 80;

  // Flow to +x: arrows are horizontal (white in most columns, few rows), heads on the right.
  const VectorFieldGrid right = make_grid(21, one, one, zero);
  write_field_png(right, marks, out_path("right"));
  const FieldPlotArea a = field_plot_area(right);
  cv::Mat mask = arrow_mask(cv::imread(out_path("right")), a, margin);
  std::vector<int> columns(mask.cols, 0), rows(mask.rows, 0);
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      if (mask.at<unsigned char>(v, u)) {
        ++columns[u];
        ++rows[v];
      }
    }
  }
  auto covered = [](const std::vector<int>& p) {
    return static_cast<double>(std::count_if(p.begin(), p.end(), [](int c) { return c > 0; })) /
           p.size();
  };
  EXPECT_GT(covered(columns), 0.75);
  EXPECT_LT(covered(rows), 0.5);
  std::vector<int> sides = head_sides(columns);
  ASSERT_GE(sides.size(), 8u);
  EXPECT_EQ(std::count(sides.begin(), sides.end(), 1), static_cast<long>(sides.size()));

  // Flow to +y: vertical arrows, heads up (image rows grow downwards, so towards small rows).
  const VectorFieldGrid up = make_grid(21, one, zero, one);
  write_field_png(up, marks, out_path("up"));
  mask = arrow_mask(cv::imread(out_path("up")), a, margin);
  std::fill(columns.begin(), columns.end(), 0);
  std::fill(rows.begin(), rows.end(), 0);
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      if (mask.at<unsigned char>(v, u)) {
        ++columns[u];
        ++rows[v];
      }
    }
  }
  EXPECT_GT(covered(rows), 0.75);
  EXPECT_LT(covered(columns), 0.5);
  sides = head_sides(rows);
  ASSERT_GE(sides.size(), 8u);
  EXPECT_EQ(std::count(sides.begin(), sides.end(), -1), static_cast<long>(sides.size()));

  // Flow to -x: heads on the left.
  const VectorFieldGrid left = make_grid(21, one, minus_one, zero);
  write_field_png(left, marks, out_path("left"));
  mask = arrow_mask(cv::imread(out_path("left")), a, margin);
  std::fill(columns.begin(), columns.end(), 0);
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) columns[u] += mask.at<unsigned char>(v, u) ? 1 : 0;
  }
  sides = head_sides(columns);
  ASSERT_GE(sides.size(), 8u);
  EXPECT_EQ(std::count(sides.begin(), sides.end(), -1), static_cast<long>(sides.size()));
}

TEST(FieldPlot, NoArrowsWhereTheAirIsStill) {
  const VectorFieldGrid g = distance_grid();  // vx = vy = 0 everywhere
  FieldMarks marks;
  marks.stagnation_W = {-5.0, 0.0};
  marks.projection_W = {-5.0, 0.3};
  write_field_png(g, marks, out_path("still"));
  const cv::Mat mask = arrow_mask(cv::imread(out_path("still")), field_plot_area(g), 80);
  EXPECT_EQ(cv::countNonZero(mask), 0);
}

TEST(FieldPlot, SameInputSameBytes) {
  const VectorFieldGrid g = make_grid(
      31, [](double x, double y) { return std::hypot(x, y); }, [](double x, double) { return x; },
      [](double, double y) { return y; });
  FieldMarks marks;
  marks.stagnation_W = {0.1, -0.2};
  marks.projection_W = {0.15, -0.1};
  marks.title = "determinism";
  const std::string first = out_path("first"), second = out_path("second");
  write_field_png(g, marks, first);
  write_field_png(g, marks, second);
  const std::string a = read_bytes(first), b = read_bytes(second);
  ASSERT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == b) << "two writes of the same picture differ";
  // And the bytes do depend on the input.
  marks.stagnation_W.x() += 0.05;
  const std::string third = out_path("third");
  write_field_png(g, marks, third);
  EXPECT_FALSE(read_bytes(third) == a);
}

TEST(FieldPlot, ConstantFieldsGiveAUniformMap) {
  FieldMarks marks;
  marks.stagnation_W = {-5.0, 0.0};
  marks.projection_W = {-5.0, 0.3};
  // All zero: degenerate colour range; the whole map is the bottom colour, no arrows.
  const VectorFieldGrid still = make_grid(5, zero, zero, zero);
  const std::string path = out_path("zero");
  ASSERT_NO_THROW(write_field_png(still, marks, path));
  const cv::Mat img = cv::imread(path);
  ASSERT_FALSE(img.empty());
  const FieldPlotArea a = field_plot_area(still);
  const cv::Rect centre(a.left_px + 100, a.top_px + 100, a.width_px - 200, a.height_px - 200);
  cv::Mat expected(centre.size(), CV_8UC3, cv::Scalar(viridis(0)[0], viridis(0)[1], viridis(0)[2]));
  EXPECT_EQ(cv::norm(img(centre), expected, cv::NORM_INF), 0.0);

  // Constant 2 m/s: top colour (range [0, 2]).
  const VectorFieldGrid steady = make_grid(
      5, [](double, double) { return 2.0; }, zero, zero);
  ASSERT_NO_THROW(write_field_png(steady, marks, path));
  const cv::Mat img2 = cv::imread(path);
  const cv::Vec3b top = viridis(255);
  cv::Mat expected2(centre.size(), CV_8UC3, cv::Scalar(top[0], top[1], top[2]));
  EXPECT_EQ(cv::norm(img2(centre), expected2, cv::NORM_INF), 0.0);
}

TEST(FieldPlot, RejectsMalformedGridsNamingTheProblem) {
  const VectorFieldGrid good = distance_grid();
  const FieldMarks marks;
  const std::string path = out_path("malformed");
  fs::remove(path);

  VectorFieldGrid g = good;
  g.speed.resize(40, 41);  // one row short
  EXPECT_NE(error_of(g, marks, path).find("grid.speed is 40 x 41"), std::string::npos)
      << error_of(g, marks, path);

  g = good;
  g.vy(3, 7) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(error_of(g, marks, path).find("grid.vy(3, 7)"), std::string::npos);
  EXPECT_NE(error_of(g, marks, path).find("nan"), std::string::npos);

  g = good;
  g.speed(0, 0) = std::numeric_limits<double>::infinity();
  EXPECT_NE(error_of(g, marks, path).find("grid.speed(0, 0)"), std::string::npos);

  g = make_grid(1, zero, zero, zero);  // one node per axis
  EXPECT_NE(error_of(g, marks, path).find("at least 2"), std::string::npos);
  g = good;
  g.y = Eigen::VectorXd::Constant(1, 0.0);
  g.vx.resize(1, 41);
  g.vy.resize(1, 41);
  g.speed.resize(1, 41);
  EXPECT_NE(error_of(g, marks, path).find("grid.y has 1 node"), std::string::npos);

  g = good;
  g.x.reverseInPlace();  // descending x
  EXPECT_NE(error_of(g, marks, path).find("grid.x must be strictly ascending"), std::string::npos);
  g = good;
  g.x[5] = g.x[4];  // a repeated node
  EXPECT_NE(error_of(g, marks, path).find("ascending"), std::string::npos);
  g = good;
  g.x[0] = -std::numeric_limits<double>::infinity();
  EXPECT_NE(error_of(g, marks, path).find("grid.x[0]"), std::string::npos);

  g = VectorFieldGrid{};  // empty
  EXPECT_NE(error_of(g, marks, path).find("grid.x has 0 nodes"), std::string::npos);

  FieldMarks bad_marks;
  bad_marks.stagnation_W.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(error_of(good, bad_marks, path).find("stagnation point"), std::string::npos);
  bad_marks = FieldMarks{};
  bad_marks.speed_max_mps = -1;
  EXPECT_NE(error_of(good, bad_marks, path).find("speed_max_mps"), std::string::npos);

  // Nothing was written for any of them; the layout query rejects malformed axes too.
  EXPECT_FALSE(fs::exists(path));
  g = good;
  g.y[3] = g.y[2] - 1;
  EXPECT_THROW(field_plot_area(g), InputError);
}

TEST(FieldPlot, UnwritablePathsThrowInputError) {
  const VectorFieldGrid g = distance_grid();
  const std::string missing_dir =
      (fs::temp_directory_path() / "airtwin_no_such_dir_4711" / "f.png").string();
  fs::remove_all(fs::path(missing_dir).parent_path());
  const std::string message = error_of(g, FieldMarks{}, missing_dir);
  EXPECT_NE(message.find(missing_dir), std::string::npos) << message;
  EXPECT_NE(message.find("cannot open"), std::string::npos) << message;

  // A directory is no file.
  EXPECT_THROW(write_field_png(g, FieldMarks{}, fs::temp_directory_path().string()), InputError);
  EXPECT_THROW(write_field_png(g, FieldMarks{}, ""), InputError);
}

TEST(FieldPlot, NonSquareAndNonUniformGridsKeepTheAxisMapping) {
  // x on [0, 3] with uneven spacing, y on [-0.5, 0.5]: a wide map, s placed by the same mapping.
  VectorFieldGrid g;
  g.x.resize(6);
  g.x << 0.0, 0.1, 0.4, 1.0, 2.2, 3.0;
  g.y = Eigen::VectorXd::LinSpaced(5, -0.5, 0.5);
  g.speed = Eigen::MatrixXd::Zero(5, 6);
  for (int i = 0; i < 6; ++i) g.speed.col(i).setConstant(g.x[i]);  // speed = x, exact bilinearly
  g.vx = Eigen::MatrixXd::Zero(5, 6);  // no arrows over the colours checked below
  g.vy = Eigen::MatrixXd::Zero(5, 6);
  FieldMarks marks;
  marks.stagnation_W = {2.5, 0.25};
  marks.projection_W = {0.5, -0.3};
  const std::string path = out_path("wide");
  write_field_png(g, marks, path);
  const cv::Mat img = cv::imread(path);
  ASSERT_FALSE(img.empty());
  const FieldPlotArea a = field_plot_area(g);
  EXPECT_GT(a.width_px, 2 * a.height_px);
  // Equal metres per pixel on both axes (3 m wide, 1 m high).
  EXPECT_NEAR((a.width_px - 1) / 3.0, (a.height_px - 1) / 1.0, 1.0);

  int n_red = 0;
  const cv::Point2d red = centroid(img, a, is_red, n_red);
  const cv::Point2d s_px = predicted_px(g, a, marks.stagnation_W);
  EXPECT_NEAR(red.x, s_px.x, 1.0);
  EXPECT_NEAR(red.y, s_px.y, 1.0);

  // Colour under x = 1.6 m (between uneven nodes) is viridis(255 * 1.6 / 3).
  const int u = static_cast<int>(std::lround(predicted_px(g, a, {1.6, 0.0}).x));
  const int v = a.top_px + 5;
  const double x = data_at(g, a, u, v).x();
  EXPECT_LE(max_channel_difference(img.at<cv::Vec3b>(v, u),
                                   viridis(static_cast<int>(std::lround(255 * x / 3.0)))),
            2);
}

}  // namespace
}  // namespace airtwin::plots
