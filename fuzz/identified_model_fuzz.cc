// Fuzz target: model.json, the identified model that `identify` writes and --model reads
// (models/identified_model.h). What the reader accepts, the writer must write.

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "models/identified_model.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  const std::string text = fuzz::text_of(data, size);
  fuzz::expect_input_error([&] {
    const IdentifiedModel model = parse_identified_model_json(text, "fuzz.json");
    (void)identified_model_json(model);
    (void)model.eq8_note();
  });
  return 0;
}
