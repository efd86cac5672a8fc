#pragma once
// What MuJoCo's visualiser reads of an mjData: the simulated time, qpos, mocap poses, and the
// kinematics computed from them (body, geom, site, camera and light poses, the tree's centres of
// mass, joint axes, tendon paths). mjv_updateScene builds a scene from these alone, so a copy of
// them shows exactly the poses the source holds, which after mj_step are those of the start of
// the last step (what Twin::object_state reports), not those of the integrated qpos.
//
// Two uses: a renderer mirrors them into its own mjData so that drawing never writes the twin's
// (renders/frame_renderer.h), and the live viewer ships them to its window process, which has its
// own copy of the model (viewer/view_frame.h).

#include <cstdint>
#include <vector>

#include <mujoco/mujoco.h>

namespace airtwin {

/// The visualised fields of one state, flattened in a fixed order (see kinematic_state.cc).
struct KinematicState {
  std::vector<mjtNum> reals;  ///< time first, then the mjtNum arrays
  std::vector<int> ints;      ///< the integer arrays (tendon wrap addresses, counts, objects)
};

/// Copies the visualised fields of `d` (a state of `m`).
KinematicState capture_kinematics(const mjModel* m, const mjData* d);

/// Writes `state` into `d` (of `m`). Throws InputError when its sizes are not those of `m`'s
/// fields (a state captured from another model).
void restore_kinematics(const mjModel* m, const KinematicState& state, mjData* d);

/// Copies the visualised fields of `src` into `dst`, both states of `m`; nothing else of `dst`
/// changes. The same as restore_kinematics(m, capture_kinematics(m, src), dst) without the copy.
void mirror_kinematics(const mjModel* m, const mjData* src, mjData* dst);

}  // namespace airtwin
