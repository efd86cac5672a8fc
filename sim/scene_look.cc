#include "sim/scene_look.h"

#include <initializer_list>

namespace airtwin {

void apply_scene_look(mjvOption* option, mjvScene* scene) {
  // The rendering: no shadows, reflections, skybox, fog or haze (the top view sees only the floor).
  for (int f : {mjRND_SHADOW, mjRND_REFLECTION, mjRND_SKYBOX, mjRND_FOG, mjRND_HAZE,
                mjRND_WIREFRAME, mjRND_SEGMENT, mjRND_IDCOLOR}) {
    scene->flags[f] = 0;
  }
  // What is drawn: geom groups 0-2, every skin, textures; no sites, no decorations.
  for (int g = 0; g < mjNGROUP; ++g) {
    option->geomgroup[g] = g <= 2;
    option->skingroup[g] = 1;
    option->sitegroup[g] = 0;
  }
  for (int f = 0; f < mjNVISFLAG; ++f) option->flags[f] = 0;
  option->flags[mjVIS_TEXTURE] = 1;
  option->flags[mjVIS_SKIN] = 1;
  option->flags[mjVIS_STATIC] = 1;
}

}  // namespace airtwin
