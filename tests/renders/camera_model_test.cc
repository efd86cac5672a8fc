// The ground-truth camera model against the scene's own geometry and MuJoCo's kinematics.

#include "renders/camera_model.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/errors.h"
#include "tests/renders/render_scene.h"

namespace airtwin {
namespace {

using testing::make_render_scene;

TEST(GroundTruthCamera, PoseAgreesWithMujocosKinematics) {
  auto s = make_render_scene({});
  const GroundTruthCamera c = GroundTruthCamera::from_model(s.model());
  // mj_forward computed cam_xpos / cam_xmat on its own.
  const int id = mj_name2id(s.model(), mjOBJ_CAMERA, "top");
  for (int r = 0; r < 3; ++r) {
    EXPECT_NEAR(c.p_WC()(r), s.d()->cam_xpos[3 * id + r], 1e-12);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(c.R_WC()(r, k), s.d()->cam_xmat[9 * id + 3 * r + k], 1e-12);
  }
  EXPECT_EQ(c.width_px(), 1024);
  EXPECT_EQ(c.height_px(), 1024);
}

TEST(GroundTruthCamera, ViewSpansTheSceneParametersHalfWidth) {
  // The scene's fovy makes 2 * camera_half_view_m of floor fill the image: a floor point at
  // x = +half_view lands on the right edge of the last column (u = W - 0.5 in pixel-centre units).
  const SceneParameters params;
  auto s = make_render_scene({});
  const GroundTruthCamera c = GroundTruthCamera::from_model(s.model());
  const double h = params.camera_half_view_m;
  EXPECT_NEAR(c.project({h, 0, 0})->x(), 1024 - 0.5, 1e-6);
  EXPECT_NEAR(c.project({-h, 0, 0})->x(), -0.5, 1e-6);
  EXPECT_NEAR(c.project({0, h, 0})->y(), -0.5, 1e-6);  // +y is up in the image
  EXPECT_NEAR(c.project({0, -h, 0})->y(), 1024 - 0.5, 1e-6);
  // (fovy goes through the MJCF as 9 significant digits of degrees)
  EXPECT_NEAR(c.focal_px(), 512.0 * params.camera_height_m / h, 1e-5);
  // The optical axis hits the image centre.
  EXPECT_NEAR(c.project({0, 0, 0})->x(), 511.5, 1e-9);
  EXPECT_NEAR(c.project({0, 0, 0})->y(), 511.5, 1e-9);
}

TEST(GroundTruthCamera, FloorPointInvertsProjection) {
  auto s = make_render_scene({});
  const GroundTruthCamera c = GroundTruthCamera::from_model(s.model());
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.3, -0.7, 0), Eigen::Vector3d(-1.2, 1.1, 0),
                                   Eigen::Vector3d(0.0, 0.01, 0)}) {
    const Eigen::Vector2d uv = *c.project(p);
    EXPECT_LT((*c.floor_point(uv) - p).norm(), 1e-9);
  }
  // A raised point projects farther from the centre than its footprint (perspective).
  const Eigen::Vector2d foot = *c.project({0.5, 0, 0}), top = *c.project({0.5, 0, 0.1});
  EXPECT_GT(top.x(), foot.x());
  // K maps camera-frame directions to the same pixels.
  const Eigen::Vector3d p_C = c.R_WC().transpose() * (Eigen::Vector3d(0.4, 0.2, 0) - c.p_WC());
  const Eigen::Vector3d h = c.intrinsics() * Eigen::Vector3d(p_C.x(), -p_C.y(), -p_C.z());
  EXPECT_LT((h.head<2>() / h.z() - *c.project({0.4, 0.2, 0})).norm(), 1e-9);
}

TEST(GroundTruthCamera, PointsBehindTheCameraHaveNoImage) {
  auto s = make_render_scene({});
  const GroundTruthCamera c = GroundTruthCamera::from_model(s.model());
  EXPECT_FALSE(c.project({0, 0, 5.0}).has_value());
  EXPECT_FALSE(c.project(c.p_WC()).has_value());
}

TEST(GroundTruthCamera, RejectsMissingOrMovingCameras) {
  EXPECT_THROW(GroundTruthCamera::from_model(make_render_scene({}).model(), "side"), InputError);
  const ModelPtr m = load_model_from_xml(R"(
<mujoco><worldbody><body name="b"><freejoint/><geom size="0.1"/>
  <camera name="onboard" pos="0 0 1"/></body></worldbody></mujoco>)",
                                         "inline");
  EXPECT_THROW(GroundTruthCamera::from_model(m.get(), "onboard"), InputError);
}

}  // namespace
}  // namespace airtwin
