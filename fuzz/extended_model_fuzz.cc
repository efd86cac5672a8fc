// Fuzz target: extended_model.json, the discrepancy analysis's model that `run --model` reads
// (models/extended_model.h). What the reader accepts, the writer must write.

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "models/extended_model.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  const std::string text = fuzz::text_of(data, size);
  (void)looks_like_extended_model(text);
  fuzz::expect_input_error([&] {
    const ExtendedModel model = parse_extended_model_json(text, "fuzz.json");
    (void)extended_model_json(model);
  });
  return 0;
}
