// The viewer's frames as bytes: every field comes back as it went, any cut or padded message is
// an InputError (never a crash), and the model sent as MJB bytes is the same model.

#include "viewer/view_frame.h"

#include <gtest/gtest.h>

#include <cstring>

#include "common/errors.h"

namespace airtwin {
namespace {

ViewFrame sample_frame() {
  ViewFrame f;
  f.index = 1234;
  f.kinematics.reals = {0.5, -1.25, 3.0e-17, 42.0};
  f.kinematics.ints = {7, -1, 3};
  f.overlay.path_W = {{-0.26, 0.25}, {0.26, 0.25}};
  f.overlay.path_references_W = {{-0.16, 0.25}, {-0.06, 0.25}};
  f.overlay.current_references_W = {{-0.06, 0.25}};
  f.overlay.zones = {{{-0.7, 0.1}, 0.21, "tracer"}, {{0.7, 0.0}, 0.21, ""}};
  f.overlay.stagnation_W = Eigen::Vector2d(0.41, -0.02);
  f.overlay.air = {{{0.0, 0.0}, {1.5, -0.5}}, {{0.15, 0.0}, {2.0, 0.0}}};
  f.overlay.caption = "line seed 1, decision 3";
  return f;
}

TEST(ViewFrame, RoundTripKeepsEveryField) {
  const ViewFrame f = sample_frame();
  const ViewFrame g = decode_view_frame(encode_view_frame(f));
  EXPECT_EQ(g.index, f.index);
  EXPECT_EQ(g.kinematics.reals, f.kinematics.reals);
  EXPECT_EQ(g.kinematics.ints, f.kinematics.ints);
  EXPECT_EQ(g.overlay.path_W, f.overlay.path_W);
  EXPECT_EQ(g.overlay.path_references_W, f.overlay.path_references_W);
  EXPECT_EQ(g.overlay.current_references_W, f.overlay.current_references_W);
  ASSERT_EQ(g.overlay.zones.size(), 2u);
  EXPECT_EQ(g.overlay.zones[0].centre_W, f.overlay.zones[0].centre_W);
  EXPECT_EQ(g.overlay.zones[0].radius_m, 0.21);
  EXPECT_EQ(g.overlay.zones[0].label, "tracer");
  EXPECT_EQ(g.overlay.zones[1].label, "");
  ASSERT_TRUE(g.overlay.stagnation_W.has_value());
  EXPECT_EQ(*g.overlay.stagnation_W, *f.overlay.stagnation_W);
  ASSERT_EQ(g.overlay.air.size(), 2u);
  EXPECT_EQ(g.overlay.air[1].p_W, f.overlay.air[1].p_W);
  EXPECT_EQ(g.overlay.air[1].v_W, f.overlay.air[1].v_W);
  EXPECT_EQ(g.overlay.caption, f.overlay.caption);
  // No stagnation point stays none.
  ViewFrame without = f;
  without.overlay.stagnation_W.reset();
  EXPECT_FALSE(decode_view_frame(encode_view_frame(without)).overlay.stagnation_W.has_value());
}

TEST(ViewFrame, CutOrPaddedMessagesAreInputErrors) {
  const std::string bytes = encode_view_frame(sample_frame());
  for (size_t n = 0; n < bytes.size(); ++n) {
    EXPECT_THROW(decode_view_frame(std::string_view(bytes).substr(0, n)), InputError) << n;
  }
  EXPECT_THROW(decode_view_frame(bytes + "x"), InputError);
  // A count far beyond the message is refused before anything is allocated for it.
  std::string huge = bytes;
  const uint64_t n = uint64_t{1} << 60;
  std::memcpy(huge.data() + sizeof(int64_t), &n, sizeof(n));
  EXPECT_THROW(decode_view_frame(huge), InputError);
}

TEST(ViewFrame, ModelBytesGiveTheSameModel) {
  ModelPtr m = load_model_from_xml(
      "<mujoco><asset><texture name='t' type='2d' builtin='checker' width='8' height='8'/>"
      "<material name='m' texture='t'/></asset><worldbody><geom type='plane' size='1 1 .1' "
      "material='m'/><body><freejoint/><geom size='0.1' mass='0.3'/></body></worldbody>"
      "</mujoco>",
      "test model");
  const std::string bytes = model_bytes(m.get());
  ModelPtr back = model_from_bytes(bytes);
  ASSERT_TRUE(back);
  EXPECT_EQ(model_bytes(back.get()), bytes);
  EXPECT_EQ(back->body_mass[1], m->body_mass[1]);
  EXPECT_THROW(model_from_bytes("not a model"), InputError);
}

}  // namespace
}  // namespace airtwin
