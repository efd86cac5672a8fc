// Fuzz target: the scenario YAML of run, batch and render (scenes/scenario.h).

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "scenes/scenario.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  const std::string text = fuzz::text_of(data, size);
  fuzz::expect_input_error([&] { (void)parse_scenario(text, "fuzz.yaml"); });
  return 0;
}
