// Fuzz target: the object-physics strings "TYPE:key=value,..." (sim/object_physics.h), applied to
// the default scene (eq. (8)'s drag) and to one whose types use the physical drag law, and
// written back.

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "sim/object_physics.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  const std::string text = fuzz::text_of(data, size);
  for (const bool physical : {false, true}) {
    fuzz::expect_input_error([&] {
      SceneParameters scene;
      if (physical) {
        scene.tracer.use_physical_drag();
        scene.cotton.use_physical_drag();
      }
      apply_object_physics(text, &scene);
      (void)object_physics_to_string(scene, ObjectType::kTracer);
      (void)object_physics_to_string(scene, ObjectType::kCotton);
    });
  }
  return 0;
}
