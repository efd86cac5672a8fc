// The OSMesa + MuJoCo context: created at the model's offscreen size, several at once, in threads.

#include "renders/offscreen_context.h"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "common/errors.h"
#include "tests/renders/render_scene.h"

namespace airtwin {
namespace {

TEST(OffscreenContext, HasTheModelsOffscreenSize) {
  auto s = testing::make_render_scene({});
  OffscreenContext context(s.model());
  EXPECT_EQ(context.width_px(), 1024);
  EXPECT_EQ(context.height_px(), 1024);
  EXPECT_EQ(context.multisamples(), 0);
  EXPECT_EQ(context.mjr()->offWidth, 1024);
  EXPECT_EQ(context.mjr()->offSamples, 0);
  EXPECT_EQ(context.mjr()->currentBuffer, mjFB_OFFSCREEN);
  EXPECT_FALSE(context.gl_renderer().empty());
}

TEST(OffscreenContext, ContextsInTwoThreadsAtOnce) {
  auto s = testing::make_render_scene({});
  int ok[2] = {0, 0};
  std::vector<std::thread> threads;
  for (int k = 0; k < 2; ++k) {
    threads.emplace_back([&, k] {
      OffscreenContext context(s.model(), 4 * k);
      context.make_current();
      ok[k] = context.mjr()->offFBO != 0 && context.mjr()->offSamples == 4 * k;
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(ok[0], 1);
  EXPECT_EQ(ok[1], 1);
}

TEST(OffscreenContext, RejectsNegativeSampleCounts) {
  auto s = testing::make_render_scene({});
  EXPECT_THROW(OffscreenContext(s.model(), -1), InputError);
}

}  // namespace
}  // namespace airtwin
