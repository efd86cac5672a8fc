#pragma once
// From a scenario to a compiled MuJoCo model: the MJCF is written in code from a SceneSpec and the
// fixed SceneParameters and compiled from memory; the wads are shaped in the compiled model and
// MuJoCo writes the result back as MJCF (export_scene: the `airtwin scene` files); the twin
// compiles that text, and the bodies of each object are indexed so that the twin can push them
// and read them back. A user's MJCF (load_scene) is indexed the same way, after checks.
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

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sim/mujoco_runtime.h"
#include "sim/scene_spec.h"

namespace airtwin {

/// Most bodies one object may have (the air forces keep a fixed scratch per object).
inline constexpr size_t kMaxObjectBodies = 64;

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
  /// The object's own physics when its spec had one (ObjectSpec::physics); unset: its type's.
  std::optional<ObjectTypeParameters> physics;
};

/// The physics `object` was built with: its own, or its type's in `params`.
const ObjectTypeParameters& physics_of(const SceneObject& object, const SceneParameters& params);

/// A compiled scene.
struct BuiltScene {
  ModelPtr model;
  std::vector<SceneObject> objects;
  int pan_joint = -1;   ///< hinge `nozzle_pan`
  int tilt_joint = -1;  ///< hinge `nozzle_tilt`
  std::string xml;      ///< the MJCF it was compiled from (for inspection)
};

/// Throws InputError naming the object (index and id) unless: the type is known, the position and
/// yaw are finite, the footprint lies on the floor, no two footprints overlap, ids are non-empty
/// and unique, and the parameters are physical (positive sizes, masses, timestep in [0.1, 5] ms).
void validate_scene(const SceneSpec& spec, const SceneParameters& params);

/// "tracer" -> kTracer, "cotton" -> kCotton; InputError naming `where` otherwise.
ObjectType parse_object_type(const std::string& name, const std::string& where);

/// The MJCF text of the scene (validates first). Headings not given are drawn from `seed`. It
/// names the files of scene_files by relative names.
std::string scene_xml(const SceneSpec& spec, const SceneParameters& params, uint64_t seed);

/// The files scene_xml's text refers to: the tracer's mesh (`hemisphere.stl`) if there is a
/// tracer, else none.
std::vector<ModelFile> scene_files(const SceneSpec& spec, const SceneParameters& params);

/// "obj<i>": the name of object i's root body.
std::string object_body_name(size_t i);

/// The scene the twin simulates: export_scene's MJCF (validated, written, compiled, wads shaped
/// from `seed`, written back by MuJoCo), compiled, with the object bodies indexed. Same arguments,
/// same model; the model of export_scene's files, to the last bit.
BuiltScene build_scene(const SceneSpec& spec, const SceneParameters& params, uint64_t seed);

/// A scene as MJCF files that stand on their own: `scene.xml` and the files it names.
struct SceneExport {
  std::string xml;
  std::vector<ModelFile> files;
};

/// The scene as MuJoCo's own MJCF: scene_xml compiled, the wads shaped from `seed`, written back
/// by MuJoCo (composites expanded, numbers to 17 digits; mujoco_runtime.h compiled_model_xml) with
/// the wads' central spheres switched off. build_scene compiles this text, so these files are
/// what the twin simulates. Validates first (InputError naming the object).
SceneExport export_scene(const SceneSpec& spec, const SceneParameters& params, uint64_t seed);

/// A user's MJCF file (e.g. an export_scene edited) as the scene of `spec`'s objects. The file
/// must provide what the twin looks up: per object i a body `obj<i>` on the world body whose
/// first joint is a free joint (a tracer: that one body; a wad: it and the element bodies under
/// it), no `obj<n>` for n past the scenario's objects, hinges `nozzle_pan` and `nozzle_tilt`,
/// camera `top`, and the twin's timestep. Nothing is reshaped: the file's bodies are simulated as
/// they are. Throws InputError "<path>: <element>: <what is wrong>; expected <what the twin
/// needs>" for the first thing missing, or for a file MuJoCo cannot load.
BuiltScene load_scene(const std::string& path, const SceneSpec& spec,
                      const SceneParameters& params);

}  // namespace airtwin
