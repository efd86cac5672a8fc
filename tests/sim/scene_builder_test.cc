// Scene assembly: a mixed scene compiles, its bodies are indexed with the paper's masses and
// shapes, the rig and camera sit where the geometry says, and bad scenarios name the object. A
// user's scene (load_scene): an export loads as the built scene, and what the twin cannot find in
// an edited one is named.

#include "sim/scene_builder.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <string>

#include "common/errors.h"
#include "common/units.h"
#include "models/nozzle_geometry.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

// "t" + i, built without operator+ (GCC 12 -O3 reports a false -Wrestrict on it).
std::string numbered(const char* prefix, int i) {
  std::string s = prefix;
  s += std::to_string(i);
  return s;
}

SceneSpec mixed_scene() {
  SceneSpec spec;
  spec.source = "mixed.yaml";
  spec.objects = {{"t0", "tracer", {0.3, 0.0}, 0.0},
                  {"c0", "cotton", {-0.3, 0.2}, std::nullopt},
                  {"t1", "tracer", {0.0, -0.5}, 1.0},
                  {"c1", "cotton", {0.5, 0.5}, std::nullopt},
                  {"t2", "tracer", {-1.2, -1.2}, std::nullopt}};
  return spec;
}

TEST(SceneBuilder, MixedSceneCompilesWithIndexedObjects) {
  const SceneParameters params;
  const BuiltScene scene = build_scene(mixed_scene(), params, 1);
  const mjModel* m = scene.model.get();
  ASSERT_EQ(scene.objects.size(), 5u);
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& o = scene.objects[i];
    // Named obj<i>, every body in its subtree, shares summing to one.
    std::string expected_name = "obj";
    expected_name += std::to_string(i);
    EXPECT_EQ(std::string(mj_id2name(m, mjOBJ_BODY, o.root_body)), expected_name);
    double share = 0.0;
    for (size_t k = 0; k < o.bodies.size(); ++k) {
      EXPECT_EQ(m->body_rootid[o.bodies[k]], o.root_body);
      share += o.area_share[k];
    }
    EXPECT_NEAR(share, 1.0, 1e-12);
    // Sections II-B and IV-C: 0.16 g tracers, 0.22 g wads.
    if (o.type == ObjectType::kTracer) {
      EXPECT_EQ(o.bodies.size(), 1u);
      EXPECT_NEAR(o.mass_kg, 0.16e-3, 1e-9);
    } else {
      EXPECT_GT(o.bodies.size(), 20u);
      EXPECT_NEAR(o.mass_kg, 0.22e-3, 1e-9);
    }
  }
  EXPECT_EQ(scene.objects[1].id, "c0");
  EXPECT_EQ(scene.objects[1].type, ObjectType::kCotton);
}

TEST(SceneBuilder, TracerIsAHemisphereOnAThinCollider) {
  const SceneParameters params;
  const BuiltScene scene = build_scene(mixed_scene(), params, 1);
  const mjModel* m = scene.model.get();
  const int b = scene.objects[0].root_body;
  const double r = 0.015;
  // Centre of mass 3R/8 above the flat face, solid-hemisphere inertia about the axis.
  EXPECT_NEAR(m->body_ipos[3 * b + 2], 3.0 / 8.0 * r, 1e-12);
  EXPECT_NEAR(m->body_inertia[3 * b + 2], 0.4 * 0.16e-3 * r * r, 1e-15);
  const int collider = mj_name2id(m, mjOBJ_GEOM, "obj0_collider");
  const int shell = mj_name2id(m, mjOBJ_GEOM, "obj0_shell");
  ASSERT_GE(collider, 0);
  ASSERT_GE(shell, 0);
  EXPECT_EQ(m->geom_type[collider], mjGEOM_CYLINDER);
  EXPECT_NEAR(m->geom_size[3 * collider], r, 1e-12);
  EXPECT_EQ(m->geom_type[shell], mjGEOM_MESH);
  EXPECT_EQ(m->geom_contype[shell], 0);
  EXPECT_EQ(m->geom_conaffinity[shell], 0);
  // The compiler recentres the mesh on its volume centroid, which for a solid hemisphere is 3R/8.
  EXPECT_NEAR(m->geom_pos[3 * shell + 2], 3.0 / 8.0 * r, 2e-4);
  // Kinetic friction from the physics triple: mu = -x3 / g.
  EXPECT_NEAR(m->geom_friction[3 * collider], -kTracerTwinPhysics.xi3 / 9.81, 1e-6);
}

TEST(SceneBuilder, NozzleExitAndJetAxisFollowEquationOne) {
  const SceneParameters params;
  BuiltScene scene = build_scene(mixed_scene(), params, 1);
  const mjModel* m = scene.model.get();
  DataPtr d = make_data(m);
  const int site = mj_name2id(m, mjOBJ_SITE, "nozzle_exit");
  ASSERT_GE(site, 0);
  const NozzleGeometry geometry;
  for (const NozzleOrientation o : {NozzleOrientation{0.0, 0.0}, NozzleOrientation{0.7, 0.4},
                                    NozzleOrientation{-2.5, deg_to_rad(50)}}) {
    d->qpos[m->jnt_qposadr[scene.pan_joint]] = o.pan_rad;
    d->qpos[m->jnt_qposadr[scene.tilt_joint]] = o.tilt_rad;
    mj_forward(m, d.get());
    const Eigen::Vector3d exit(d->site_xpos[3 * site], d->site_xpos[3 * site + 1],
                               d->site_xpos[3 * site + 2]);
    EXPECT_NEAR(exit.z(), 1.43, 1e-12);
    // The jet leaves along the site's -z axis; where it meets the floor is eq. (1)'s c.
    const Eigen::Vector3d axis(-d->site_xmat[9 * site + 2], -d->site_xmat[9 * site + 5],
                               -d->site_xmat[9 * site + 8]);
    const Eigen::Vector3d hit = exit + axis * (exit.z() / -axis.z());
    const Eigen::Vector2d c = projection_point(geometry, o);
    EXPECT_NEAR(hit.x(), c.x(), 1e-9);
    EXPECT_NEAR(hit.y(), c.y(), 1e-9);
  }
}

TEST(SceneBuilder, TopCameraSeesTheWorkspaceAtTheRigResolution) {
  const SceneParameters params;
  const BuiltScene scene = build_scene(mixed_scene(), params, 1);
  const mjModel* m = scene.model.get();
  const int cam = mj_name2id(m, mjOBJ_CAMERA, "top");
  ASSERT_GE(cam, 0);
  EXPECT_EQ(m->vis.global.offwidth, 1024);
  EXPECT_EQ(m->vis.global.offheight, 1024);
  // Straight down, centred on the origin, at least 2.5 x 2.5 m of floor in view.
  EXPECT_NEAR(m->cam_pos[3 * cam], 0.0, 1e-12);
  EXPECT_NEAR(m->cam_pos[3 * cam + 1], 0.0, 1e-12);
  const double half_view = m->cam_pos[3 * cam + 2] * std::tan(deg_to_rad(m->cam_fovy[cam]) / 2);
  EXPECT_GE(half_view, 1.25);
  // The floor is at least 3 x 3 m and textured.
  const int floor = mj_name2id(m, mjOBJ_GEOM, "floor");
  EXPECT_GE(m->geom_size[3 * floor], 1.5);
  EXPECT_GE(m->geom_matid[floor], 0);
  EXPECT_GE(m->mat_texid[m->geom_matid[floor]], 0);
}

TEST(SceneBuilder, CottonShapeComesFromTheSeed) {
  const SceneParameters params;
  const BuiltScene a = build_scene(mixed_scene(), params, 1);
  const BuiltScene again = build_scene(mixed_scene(), params, 1);
  const BuiltScene other = build_scene(mixed_scene(), params, 2);
  const SceneObject& wad = a.objects[1];
  double same = 0.0, different = 0.0, between_wads = 0.0;
  for (size_t k = 1; k < wad.bodies.size(); ++k) {
    for (int axis = 0; axis < 3; ++axis) {
      const int i = 3 * wad.bodies[k] + axis;
      same += std::abs(a.model->body_pos[i] - again.model->body_pos[i]);
      different += std::abs(a.model->body_pos[i] - other.model->body_pos[i]);
      between_wads +=
          std::abs(a.model->body_pos[i] - a.model->body_pos[3 * a.objects[3].bodies[k] + axis]);
    }
  }
  EXPECT_EQ(same, 0.0);
  EXPECT_GT(different, 1e-3);
  EXPECT_GT(between_wads, 1e-3);  // two wads of one scene differ too
  EXPECT_EQ(a.xml, again.xml);
}

TEST(SceneBuilder, BuffersGrowWithTheObjects) {
  SceneSpec small, large;
  small.objects = {{"c", "cotton", {0.0, 0.5}, 0.0}};
  for (int i = 0; i < 6; ++i) {
    large.objects.push_back({numbered("c", i), "cotton", {-0.6 + 0.2 * i, 0.5}, 0.0});
  }
  const SceneParameters params;
  const BuiltScene a = build_scene(small, params, 1), b = build_scene(large, params, 1);
  EXPECT_GT(b.model->njmax, a.model->njmax);
  EXPECT_GT(b.model->nconmax, a.model->nconmax);
}

// Expects build_scene to throw an InputError whose message contains every one of `parts`.
void expect_input_error(const SceneSpec& spec, std::initializer_list<std::string> parts) {
  try {
    build_scene(spec, SceneParameters{}, 1);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    for (const std::string& p : parts) {
      EXPECT_NE(what.find(p), std::string::npos) << "'" << p << "' missing from: " << what;
    }
  }
}

TEST(SceneBuilder, BadScenariosNameTheObject) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  SceneSpec spec;
  spec.source = "bad.yaml";
  spec.objects = {{"a", "tracer", {0.0, 0.3}, 0.0}, {"b", "foam", {0.3, 0.3}, 0.0}};
  expect_input_error(spec, {"bad.yaml", "objects[1]", "'b'", "unknown type 'foam'"});
  spec.objects = {{"a", "tracer", {0.0, 0.3}, 0.0}, {"b", "tracer", {nan, 0.3}, 0.0}};
  expect_input_error(spec, {"objects[1]", "'b'", "finite"});
  spec.objects = {{"a", "tracer", {0.0, 0.3}, 0.0}, {"b", "tracer", {0.02, 0.3}, 0.0}};
  expect_input_error(spec, {"objects[1]", "'b'", "overlaps", "'a'"});
  spec.objects = {{"a", "cotton", {0.0, 0.3}, 0.0}, {"b", "tracer", {0.04, 0.3}, 0.0}};
  expect_input_error(spec, {"'b'", "overlaps", "'a'"});
  spec.objects = {{"a", "tracer", {0.0, 0.3}, 0.0}, {"far", "tracer", {1.995, 0.0}, 0.0}};
  expect_input_error(spec, {"objects[1]", "'far'", "outside the floor"});
  spec.objects = {{"a", "tracer", {0.0, 0.3}, 0.0}, {"a", "tracer", {0.5, 0.3}, 0.0}};
  expect_input_error(spec, {"objects[1]", "'a'", "used twice"});
  spec.objects = {{"a", "tracer", {0.0, 0.3}, nan}};
  expect_input_error(spec, {"'a'", "yaw"});
}

TEST(SceneBuilder, BadParametersAreInputErrors) {
  SceneSpec spec;
  spec.objects = {{"a", "tracer", {0.0, 0.3}, 0.0}};
  SceneParameters params;
  params.tracer.mass_kg = -1.0;
  EXPECT_THROW(build_scene(spec, params, 1), InputError);
  params = SceneParameters{};
  params.timestep_s = 0.05;
  EXPECT_THROW(build_scene(spec, params, 1), InputError);
  params = SceneParameters{};
  params.cotton.static_friction_ratio = 0.5;
  EXPECT_THROW(build_scene(spec, params, 1), InputError);
}

// An object's own physics (ObjectSpec::physics) is compiled into its bodies: its mass, split over
// a wad's elements, and its friction on its geoms; the other objects keep their type's. Its
// geometry stays the type's, and a bad value names the object.
TEST(SceneBuilder, AnObjectsOwnPhysicsReachesItsBodies) {
  SceneSpec spec = mixed_scene();
  SceneParameters params;
  params.tracer.use_physical_drag();
  params.cotton.use_physical_drag();
  ObjectTypeParameters tracer = params.tracer, cotton = params.cotton;
  tracer.mass_kg = 0.15e-3;
  tracer.kinetic_friction = tracer.physical_kinetic_friction = 0.47;
  cotton.mass_kg = 0.24e-3;
  cotton.kinetic_friction = cotton.physical_kinetic_friction = 0.55;
  spec.objects[2].physics = tracer;  // t1
  spec.objects[3].physics = cotton;  // c1
  const BuiltScene scene = build_scene(spec, params, 1);
  const mjModel* m = scene.model.get();
  const double expected_mass[5] = {0.16e-3, 0.22e-3, 0.15e-3, 0.24e-3, 0.16e-3};
  const double expected_mu[5] = {params.tracer.kinetic_friction, params.cotton.kinetic_friction,
                                 0.47, 0.55, params.tracer.kinetic_friction};
  for (size_t i = 0; i < 5; ++i) {
    const SceneObject& o = scene.objects[i];
    EXPECT_NEAR(o.mass_kg, expected_mass[i], 1e-12) << o.id;
    EXPECT_EQ(o.physics.has_value(), i == 2 || i == 3) << o.id;
    EXPECT_EQ(physics_of(o, params).mass_kg,
              i == 2 || i == 3 ? expected_mass[i] : params.of(o.type).mass_kg);
    int colliding = 0;
    for (int g = 0; g < m->ngeom; ++g) {
      if (m->body_rootid[m->geom_bodyid[g]] != o.root_body || m->geom_contype[g] == 0) continue;
      EXPECT_NEAR(m->geom_friction[3 * g], expected_mu[i], 1e-12) << o.id;
      ++colliding;
    }
    EXPECT_GT(colliding, 0) << o.id;
  }
  tracer.diameter_m = 0.04;
  spec.objects[2].physics = tracer;
  try {
    build_scene(spec, params, 1);
    ADD_FAILURE() << "a diameter of its own was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'t1'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("diameter"), std::string::npos) << e.what();
  }
  tracer.diameter_m = params.tracer.diameter_m;
  tracer.mass_kg = -1.0;
  spec.objects[2].physics = tracer;
  EXPECT_THROW(build_scene(spec, params, 1), InputError);
}

// export_scene's files written to a fresh folder, with `edit` applied to scene.xml's text; the
// path of scene.xml.
std::string write_export(const std::string& name, const SceneSpec& spec,
                         const std::function<std::string(std::string)>& edit) {
  const std::string dir = testing::fresh_scratch_dir(name);
  const SceneExport mjcf = export_scene(spec, SceneParameters{}, 2);
  std::ofstream(dir + "/scene.xml", std::ios::binary) << edit(mjcf.xml);
  for (const ModelFile& f : mjcf.files)
    std::ofstream(dir + "/" + f.name, std::ios::binary) << f.bytes;
  return dir + "/scene.xml";
}

// The message of load_scene's InputError ("" if it loads).
std::string load_error(const std::string& path, const SceneSpec& spec) {
  try {
    load_scene(path, spec, SceneParameters{});
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expect_contains(const std::string& text, const std::string& part) {
  EXPECT_NE(text.find(part), std::string::npos) << "'" << part << "' not in: " << text;
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

TEST(SceneBuilder, LoadedExportIsTheBuiltSceneIndexedAlike) {
  const SceneSpec spec = mixed_scene();
  const std::string path = write_export("scene_loaded", spec, [](std::string x) { return x; });
  const BuiltScene built = build_scene(spec, SceneParameters{}, 2);
  const BuiltScene loaded = load_scene(path, spec, SceneParameters{});
  EXPECT_EQ(loaded.xml, built.xml);
  EXPECT_EQ(loaded.pan_joint, built.pan_joint);
  EXPECT_EQ(loaded.tilt_joint, built.tilt_joint);
  ASSERT_EQ(loaded.objects.size(), built.objects.size());
  for (size_t i = 0; i < built.objects.size(); ++i) {
    EXPECT_EQ(loaded.objects[i].bodies, built.objects[i].bodies);
    EXPECT_EQ(loaded.objects[i].area_share, built.objects[i].area_share);
    EXPECT_EQ(loaded.objects[i].mass_kg, built.objects[i].mass_kg);
  }
}

TEST(SceneBuilder, UserScenesNameWhatTheTwinCannotFind) {
  const SceneSpec spec = mixed_scene();
  const auto error_of = [&](const std::string& name, const std::string& from,
                            const std::string& to) {
    return load_error(
        write_export(name, spec, [&](std::string x) { return replaced(x, from, to); }), spec);
  };
  // Each line names the file, the element, and what the twin expected.
  expect_contains(
      error_of("scene_timestep", "timestep=\"0.0025000000000000001\"", "timestep=\"0.002\""),
      "scene.xml: option timestep is 0.002 s; expected 0.0025 s");
  expect_contains(error_of("scene_pan", "joint name=\"nozzle_pan\"", "joint name=\"pan\""),
                  "scene.xml: joint 'nozzle_pan' not found; expected a hinge");
  expect_contains(error_of("scene_camera", "camera name=\"top\"", "camera name=\"overhead\""),
                  "scene.xml: camera 'top' not found; expected a camera named");
  expect_contains(error_of("scene_free", "<joint name=\"obj2_free\" type=\"free\"/>", ""),
                  "body 'obj2' (tracer 't1', objects[2] of the scenario) has no "
                  "free joint as its first joint; expected a body named 'obj2'");
  // A scenario of fewer objects than the file's.
  SceneSpec fewer = spec;
  fewer.objects.pop_back();
  const std::string path = write_export("scene_extra", spec, [](std::string x) { return x; });
  expect_contains(load_error(path, fewer),
                  "body 'obj4' has no object in the scenario (4 objects); "
                  "expected object bodies obj0 to obj3 only");
  // A tracer of the scenario where the file has a wad.
  SceneSpec swapped = spec;
  swapped.objects[1].type = "tracer";
  expect_contains(load_error(path, swapped),
                  "body 'obj1' (tracer 'c0', objects[1] of the scenario) has 27 "
                  "bodies; expected a tracer to be one body");
  expect_contains(load_error(path + ".missing", spec), "no such file");
}

TEST(ObjectTypeParameters, ReproduceTheIdentifiedDynamics) {
  // The mapping of eq. (8) to drag and friction inverts exactly.
  for (const ObjectDynamics& xi : {kTracerDynamics, kCottonDynamics}) {
    const ObjectDynamics back = ObjectTypeParameters::from_dynamics(xi, 0.03, 1e-4).dynamics();
    EXPECT_NEAR(back.xi1, xi.xi1, 1e-12);
    EXPECT_NEAR(back.xi2, xi.xi2, 1e-12);
    EXPECT_NEAR(back.xi3, xi.xi3, 1e-12);
  }
  EXPECT_NEAR(ObjectTypeParameters::tracer().air_gain,
              kTracerTwinPhysics.xi2 / -kTracerTwinPhysics.xi1, 1e-12);
  EXPECT_NEAR(ObjectTypeParameters::cotton().dynamics().xi3, kCottonTwinPhysics.xi3, 1e-12);
  // eq. (8) has one friction, fitted on data that include the starts: the mirror has no static
  // friction beyond it.
  EXPECT_EQ(ObjectTypeParameters::tracer().static_friction_ratio, 1.0);
  EXPECT_EQ(ObjectTypeParameters::cotton().static_friction_ratio, 1.0);
}

}  // namespace
}  // namespace airtwin
