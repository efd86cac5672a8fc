#pragma once
// How the twin's scene is drawn by MuJoCo's visualiser, wherever it is drawn: the camera frames
// (renders/frame_renderer.h) and the live viewer's window (viewer/viewer_window.h) show the same
// thing, so that a window's picture can be checked against a camera frame (docs/viewer.md).
//
// The look (docs/rendering.md): no shadows, reflections, skybox, fog or haze; geom groups 0-2
// (floor, visual meshes, rig; the colliders of group 3 stay hidden); skins (cotton wads) and
// textures; no sites and no decorations (joints, contacts, centres of mass, lights, cameras).

#include <mujoco/mujoco.h>

namespace airtwin {

/// Sets `option` (after mjv_defaultOption) and the rendering flags of `scene` (after
/// mjv_makeScene) to the look above.
void apply_scene_look(mjvOption* option, mjvScene* scene);

}  // namespace airtwin
