// Fuzz target: the --effect strings of collect and batch (sim/effects.h): parsed, written back,
// and applied to the twin's default parameters.

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "sim/effects.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  const std::string text = fuzz::text_of(data, size);
  fuzz::expect_input_error([&] {
    const Effect effect = parse_effect(text);
    (void)effect_to_string(effect);
    TwinParameters params;
    apply_effect(effect, &params);
  });
  return 0;
}
