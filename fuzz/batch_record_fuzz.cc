// Fuzz target: a batch's run records, runs/<scenario>/seed-<n>.json (runs/batch_record.h), which
// resuming a batch, batch-merge and the report read back.

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "runs/batch_record.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  const std::string text = fuzz::text_of(data, size);
  fuzz::expect_input_error([&] { (void)parse_record(text, "fuzz.json"); });
  return 0;
}
