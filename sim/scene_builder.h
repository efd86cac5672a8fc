#pragma once
// From a scenario to a compiled MuJoCo model: the MJCF is written in code from a SceneSpec and the
// fixed SceneParameters, loaded from memory, and the bodies of each object are indexed so that the
// twin can push them and read them back.
//
// The scene (MuJoCo 2.2, see shared/notes/stack.md for why the colliders look like this):
//  - floor: a textured plane, 2 * floor_half_size_m wide, centred on the origin below the nozzle;
//    friction 0, so the objects' own coefficients decide (MuJoCo takes the max of the pair).
//  - nozzle rig: hung from a rod above the origin; body `nozzle_pan` turns about world z (hinge
//    `nozzle_pan`), body `nozzle_tilt` about the pan body's -y (hinge `nozzle_tilt`), so that tilt
//    phi swings the jet toward the pan direction as in eq. (1). The nozzle exit (site
//    `nozzle_exit`) is on the tilt axis, nozzle_height_m above the floor. No collisions: the twin
//    sets the two joints kinematically from the servo model.
//  - camera `top`: straight down from camera_height_m, image x = world x, image up = world +y,
//    fovy so that 2 * camera_half_view_m of floor fills the square image; offscreen buffer
//    camera_resolution_px square.
//  - tracer i: body `obj<i>` with a freejoint; a thin cylinder collider (radius R, 4 mm high),
//    the hemisphere mesh as visual only, explicit inertia of a solid hemisphere with its centre of
//    mass 3R/8 above the flat face.
//  - cotton i: body `obj<i>` with a freejoint holding a MuJoCo `ellipsoid` composite (26 sphere
//    elements on radial sliders, coupled by soft equality constraints, drawn by a white skin). Its
//    rest shape is made irregular after compilation: per-axis extents and per-element radii drawn
//    from the seed (cotton_irregularity).
// All object bodies are in the subtree of `obj<i>` (i = index in SceneSpec::objects).

#include <cstdint>
#include <string>
#include <vector>

#include "sim/mujoco_runtime.h"
#include "sim/scene_spec.h"

namespace airtwin {

/// One object of a compiled scene.
struct SceneObject {
  std::string id;
  ObjectType type = ObjectType::kTracer;
  int root_body = -1;       ///< the `obj<i>` body (carries the freejoint)
  std::vector<int> bodies;  ///< every body of the object, root first
  /// Per body: its share of the object's horizontally projected area (sums to 1). The air
  /// force, and the object's reported position, are split and weighted by it.
  std::vector<double> area_share;
  double mass_kg = 0.0;  ///< total mass of the bodies, from the compiled model
};

/// A compiled scene.
struct BuiltScene {
  ModelPtr model;
  std::vector<SceneObject> objects;
  int pan_joint = -1;   ///< hinge `nozzle_pan`
  int tilt_joint = -1;  ///< hinge `nozzle_tilt`
  std::string xml;      ///< the MJCF it was compiled from (for inspection and saving)
};

/// Throws InputError naming the object (index and id) unless: the type is known, the position and
/// yaw are finite, the footprint lies on the floor, no two footprints overlap, ids are non-empty
/// and unique, and the parameters are physical (positive sizes, masses, timestep in [0.1, 5] ms).
void validate_scene(const SceneSpec& spec, const SceneParameters& params);

/// "tracer" -> kTracer, "cotton" -> kCotton; InputError naming `where` otherwise.
ObjectType parse_object_type(const std::string& name, const std::string& where);

/// The MJCF text of the scene (validates first). Headings not given are drawn from `seed`.
std::string scene_xml(const SceneSpec& spec, const SceneParameters& params, uint64_t seed);

/// Validates, writes and compiles the scene, shapes the cotton wads from `seed`, and indexes the
/// object bodies. Same arguments, same model.
BuiltScene build_scene(const SceneSpec& spec, const SceneParameters& params, uint64_t seed);

}  // namespace airtwin
