// The visualised fields of an mjData: captured and restored into another mjData, or mirrored,
// they make MuJoCo's visualiser build the same scene as from the source (the independent truth:
// mjv_updateScene on both); a state of another model is refused.

#include "sim/kinematic_state.h"

#include <gtest/gtest.h>

#include <mujoco/mujoco.h>

#include "common/errors.h"
#include "sim/mujoco_runtime.h"

namespace airtwin {
namespace {

// A falling box on a free joint, a swinging arm on a hinge, a site, a camera, a light and a
// spatial tendon: every kind of field the visualiser reads.
constexpr char kModel[] = R"(
<mujoco>
  <worldbody>
    <light pos="0 0 3"/>
    <camera name="c" pos="0 -2 1" xyaxes="1 0 0 0 0.5 1"/>
    <geom type="plane" size="2 2 0.1"/>
    <site name="anchor" pos="0 0 1.5"/>
    <body name="box" pos="0 0 1">
      <freejoint/>
      <geom type="box" size="0.1 0.1 0.1"/>
    </body>
    <body name="arm" pos="0.5 0 1">
      <joint type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
      <site name="tip" pos="0.3 0 0"/>
    </body>
  </worldbody>
  <tendon><spatial><site site="anchor"/><site site="tip"/></spatial></tendon>
</mujoco>)";

struct Fixture {
  ModelPtr m = load_model_from_xml(kModel, "test model");
  DataPtr d = make_data(m.get());
  Fixture() {
    d->qvel[m->nv - 1] = 2.0;  // the arm swings
    for (int k = 0; k < 50; ++k) mj_step(m.get(), d.get());
  }
};

// The scene MuJoCo's visualiser builds from `d`, seen from camera "c": the geoms' poses.
std::vector<float> scene_of(const mjModel* m, mjData* d) {
  mjvScene scene;
  mjv_defaultScene(&scene);
  mjv_makeScene(m, &scene, 100);
  mjvOption option;
  mjv_defaultOption(&option);
  mjvCamera camera;
  mjv_defaultCamera(&camera);
  camera.type = mjCAMERA_FIXED;
  camera.fixedcamid = 0;
  mjv_updateScene(m, d, &option, nullptr, &camera, mjCAT_ALL, &scene);
  std::vector<float> poses;
  for (int i = 0; i < scene.ngeom; ++i) {
    const mjvGeom& g = scene.geoms[i];
    poses.insert(poses.end(), g.pos, g.pos + 3);
    poses.insert(poses.end(), g.mat, g.mat + 9);
    poses.insert(poses.end(), g.size, g.size + 3);
  }
  for (int k = 0; k < 3; ++k) poses.push_back(scene.camera[0].pos[k]);
  mjv_freeScene(&scene);
  return poses;
}

TEST(KinematicState, RestoredStateBuildsTheSameScene) {
  Fixture f;
  const KinematicState state = capture_kinematics(f.m.get(), f.d.get());
  EXPECT_EQ(state.reals.front(), f.d->time);
  DataPtr copy = make_data(f.m.get());
  restore_kinematics(f.m.get(), state, copy.get());
  const std::vector<float> expected = scene_of(f.m.get(), f.d.get());
  ASSERT_FALSE(expected.empty());
  EXPECT_EQ(scene_of(f.m.get(), copy.get()), expected);
  // A fresh mjData (the bodies at their initial poses) builds another scene: the test can fail.
  DataPtr fresh = make_data(f.m.get());
  mj_forward(f.m.get(), fresh.get());
  EXPECT_NE(scene_of(f.m.get(), fresh.get()), expected);
}

TEST(KinematicState, MirrorEqualsCaptureAndRestore) {
  Fixture f;
  DataPtr mirrored = make_data(f.m.get());
  mirror_kinematics(f.m.get(), f.d.get(), mirrored.get());
  const KinematicState a = capture_kinematics(f.m.get(), f.d.get());
  const KinematicState b = capture_kinematics(f.m.get(), mirrored.get());
  EXPECT_EQ(a.reals, b.reals);
  EXPECT_EQ(a.ints, b.ints);
}

TEST(KinematicState, StateOfAnotherModelIsRefused) {
  Fixture f;
  const KinematicState state = capture_kinematics(f.m.get(), f.d.get());
  ModelPtr other = load_model_from_xml(
      "<mujoco><worldbody><body><freejoint/><geom size='0.1'/></body></worldbody></mujoco>",
      "other");
  DataPtr d = make_data(other.get());
  EXPECT_THROW(restore_kinematics(other.get(), state, d.get()), InputError);
}

}  // namespace
}  // namespace airtwin
