// The top-view renderer against independent truths: where MuJoCo draws a tracer agrees with the
// ground-truth pinhole model, the floor fills the frame, renders repeat bit for bit, the twin's
// state is left untouched, cotton skins show, and renderers in two threads agree.

#include "renders/frame_renderer.h"

#include <gtest/gtest.h>

#include <cstring>
#include <thread>
#include <vector>

#include "common/errors.h"
#include "renders/camera_model.h"
#include "tests/renders/render_scene.h"

namespace airtwin {
namespace {

using testing::bright_blob;
using testing::make_render_scene;
using testing::object_centre_W;

// White objects saturate at 255 on the ~80-90 grey floor; anything above this is object (or rig).
constexpr int kBrightGrey = 200;

bool same_bytes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && a.isContinuous() && b.isContinuous() &&
         std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

TEST(FrameRenderer, TracerAppearsWhereTheCameraModelProjectsIt) {
  // One tracer off-centre in both axes (away from the nozzle rig in the middle of the view).
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(0.42, -0.27), Eigen::Vector2d(-0.9, 0.75)}) {
    auto s = make_render_scene({{"t", "tracer", p, 0.0}});
    FrameRenderer renderer(s.model());
    const cv::Mat image = renderer.render(s.d(), 0);
    const GroundTruthCamera camera = GroundTruthCamera::from_model(s.model());
    // The blob of the white hemisphere; its centre is ~1/2 R above the floor (3R/8 centre of mass).
    const Eigen::Vector2d expected_px = *camera.project(object_centre_W(s, 0));
    const auto blob = bright_blob(image, expected_px, 25.0, kBrightGrey);
    // A 3 cm hemisphere is ~11 px across at 2.6 mm/px: ~100 px of area.
    EXPECT_GT(blob.count, 60) << p.transpose();
    EXPECT_LT(blob.count, 160) << p.transpose();
    EXPECT_NEAR(blob.centroid_px.x(), expected_px.x(), 1.5) << p.transpose();
    EXPECT_NEAR(blob.centroid_px.y(), expected_px.y(), 1.5) << p.transpose();
    // Back to the floor: within a few mm of where the tracer stands.
    const Eigen::Vector3d floor_W = *camera.floor_point(blob.centroid_px);
    EXPECT_LT((floor_W.head<2>() - p).norm(), 4e-3) << p.transpose();
  }
}

TEST(FrameRenderer, FrameIs1024SquareBgrAndTheFloorFillsIt) {
  auto s = make_render_scene({{"t", "tracer", {0.3, 0.3}, 0.0}});
  FrameRenderer renderer(s.model());
  const cv::Mat image = renderer.render(s.d(), 0);
  ASSERT_EQ(image.rows, 1024);
  ASSERT_EQ(image.cols, 1024);
  ASSERT_EQ(image.type(), CV_8UC3);
  EXPECT_EQ(renderer.width_px(), 1024);
  EXPECT_EQ(renderer.height_px(), 1024);
  // Every border pixel is floor: grey (neither MuJoCo's black background nor an object), and
  // the checker texture is there (two distinct grey levels along the border).
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  int lo = 255, hi = 0;
  for (int k = 0; k < 1024; ++k) {
    for (const auto& [r, c] :
         {std::pair{0, k}, std::pair{1023, k}, std::pair{k, 0}, std::pair{k, 1023}}) {
      const int g = grey.at<unsigned char>(r, c);
      lo = std::min(lo, g);
      hi = std::max(hi, g);
    }
  }
  EXPECT_GT(lo, 50);
  EXPECT_LT(hi, 180);
  EXPECT_GE(hi - lo, 4);
}

TEST(FrameRenderer, RendersAreDeterministicAndNoiseFollowsTheSeed) {
  auto s =
      make_render_scene({{"t", "tracer", {0.3, -0.2}, 0.0}, {"c", "cotton", {-0.3, 0.2}, 0.5}});
  FrameRenderer clean(s.model());
  EXPECT_TRUE(same_bytes(clean.render(s.d(), 0), clean.render(s.d(), 7)));
  // Noise and blur: same seed and frame -> same bytes, also from a second renderer.
  RenderOptions options;
  options.noise_sigma_grey = 3.0;
  options.blur_sigma_px = 0.8;
  options.seed = 42;
  FrameRenderer noisy_a(s.model(), options), noisy_b(s.model(), options);
  const cv::Mat a5 = noisy_a.render(s.d(), 5);
  EXPECT_TRUE(same_bytes(a5, noisy_b.render(s.d(), 5)));
  EXPECT_TRUE(same_bytes(a5, noisy_a.render(s.d(), 5)));
  // Another frame index or seed -> other noise.
  EXPECT_FALSE(same_bytes(a5, noisy_a.render(s.d(), 6)));
  options.seed = 43;
  FrameRenderer noisy_c(s.model(), options);
  EXPECT_FALSE(same_bytes(a5, noisy_c.render(s.d(), 5)));
  // The noise is what was asked for: the residual against the blurred clean frame has sigma ~3.
  RenderOptions blur_only = options;
  blur_only.noise_sigma_grey = 0.0;
  FrameRenderer blurred(s.model(), blur_only);
  cv::Mat residual;
  cv::subtract(a5, blurred.render(s.d(), 5), residual, cv::noArray(), CV_32F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(residual.reshape(1), mean, stddev);
  EXPECT_NEAR(stddev[0], 3.0, 0.1);
  EXPECT_NEAR(mean[0], 0.0, 0.05);
}

TEST(FrameRenderer, LeavesTheStateUntouched) {
  auto s =
      make_render_scene({{"t", "tracer", {0.3, -0.2}, 0.0}, {"c", "cotton", {-0.3, 0.2}, 0.5}});
  for (int k = 0; k < 20; ++k) mj_step(s.model(), s.d());
  const mjData* d = s.d();
  const std::vector<unsigned char> buffer(
      static_cast<const unsigned char*>(d->buffer),
      static_cast<const unsigned char*>(d->buffer) + d->nbuffer);
  const std::vector<mjtNum> stack(d->stack, d->stack + d->nstack);
  const int pstack = d->pstack, maxuse = d->maxuse_stack;
  const double time = d->time;
  FrameRenderer renderer(s.model());
  renderer.render(s.d(), 0);
  // Every byte of mjData's main buffer (qpos, qvel, poses, ...) and of its stack, and the counters.
  EXPECT_EQ(std::memcmp(buffer.data(), d->buffer, buffer.size()), 0);
  EXPECT_EQ(std::memcmp(stack.data(), d->stack, stack.size() * sizeof(mjtNum)), 0);
  EXPECT_EQ(d->pstack, pstack);
  EXPECT_EQ(d->maxuse_stack, maxuse);
  EXPECT_EQ(d->time, time);
}

TEST(FrameRenderer, CottonWadsRenderAsBrightBlobs) {
  auto s = make_render_scene(
      {{"c", "cotton", {-0.35, 0.3}, 0.4}, {"c2", "cotton", {0.5, 0.1}, std::nullopt}});
  FrameRenderer renderer(s.model());
  const cv::Mat image = renderer.render(s.d(), 0);
  const GroundTruthCamera camera = GroundTruthCamera::from_model(s.model());
  for (size_t i = 0; i < 2; ++i) {
    const Eigen::Vector2d expected_px = *camera.project(object_centre_W(s, i));
    // A ~5 cm wad (+-20 %) is ~19 px across: 150-600 px of skin.
    const auto blob = bright_blob(image, expected_px, 30.0, kBrightGrey);
    EXPECT_GT(blob.count, 150) << i;
    EXPECT_LT(blob.count, 600) << i;
    EXPECT_NEAR(blob.centroid_px.x(), expected_px.x(), 3.0) << i;
    EXPECT_NEAR(blob.centroid_px.y(), expected_px.y(), 3.0) << i;
  }
  // Nothing bright where there is no object (a ring of floor between the two wads).
  const Eigen::Vector2d empty_px = *camera.project(Eigen::Vector3d(0.1, -0.4, 0.0));
  EXPECT_EQ(bright_blob(image, empty_px, 30.0, kBrightGrey).count, 0);
}

TEST(FrameRenderer, RenderersInTwoThreadsAgreeWithOneThread) {
  auto s =
      make_render_scene({{"t", "tracer", {0.2, 0.4}, 0.0}, {"c", "cotton", {-0.4, -0.1}, 0.2}});
  const cv::Mat reference = FrameRenderer(s.model()).render(s.d(), 0);
  // Two threads, each with its own context, rendering the same (read-only) state at once.
  cv::Mat images[2];
  std::vector<std::thread> threads;
  for (int k = 0; k < 2; ++k) {
    threads.emplace_back([&, k] {
      FrameRenderer renderer(s.model());
      for (int frame = 0; frame < 3; ++frame) images[k] = renderer.render(s.d(), frame);
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_TRUE(same_bytes(images[0], reference));
  EXPECT_TRUE(same_bytes(images[1], reference));
}

TEST(FrameRenderer, TwoRenderersTakeTurnsOnOneThread) {
  auto a = make_render_scene({{"t", "tracer", {0.2, 0.4}, 0.0}});
  auto b = make_render_scene({{"t", "tracer", {-0.5, -0.3}, 0.0}});
  FrameRenderer ra(a.model()), rb(b.model());
  const cv::Mat a0 = ra.render(a.d(), 0), b0 = rb.render(b.d(), 0);
  EXPECT_FALSE(same_bytes(a0, b0));
  EXPECT_TRUE(same_bytes(ra.render(a.d(), 1), a0));
  EXPECT_TRUE(same_bytes(rb.render(b.d(), 1), b0));
}

TEST(FrameRenderer, MultisamplingIsAvailableAndLooksAlike) {
  auto s = make_render_scene({{"t", "tracer", {0.42, -0.27}, 0.0}});
  RenderOptions options;
  options.multisamples = 4;
  const cv::Mat smooth = FrameRenderer(s.model(), options).render(s.d(), 0);
  const cv::Mat plain = FrameRenderer(s.model()).render(s.d(), 0);
  cv::Mat diff;
  cv::absdiff(smooth, plain, diff);
  EXPECT_LT(cv::mean(diff)[0], 2.0);
  const Eigen::Vector2d expected_px =
      *GroundTruthCamera::from_model(s.model()).project(object_centre_W(s, 0));
  const auto blob = bright_blob(smooth, expected_px, 25.0, kBrightGrey);
  EXPECT_NEAR(blob.centroid_px.x(), expected_px.x(), 1.5);
  EXPECT_NEAR(blob.centroid_px.y(), expected_px.y(), 1.5);
}

TEST(FrameRenderer, BadInputThrowsNamingIt) {
  auto s = make_render_scene({{"t", "tracer", {0.2, 0.4}, 0.0}});
  RenderOptions bad;
  bad.noise_sigma_grey = -1.0;
  EXPECT_THROW(FrameRenderer(s.model(), bad), InputError);
  bad = RenderOptions{};
  bad.multisamples = -2;
  EXPECT_THROW(FrameRenderer(s.model(), bad), InputError);
  try {
    FrameRenderer renderer(s.model(), RenderOptions{}, "side");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'side'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace airtwin
