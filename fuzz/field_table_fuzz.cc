// Fuzz target: the coefficient table of eq. (3) (models/field_table.h), the CSV every --table
// reads. What the reader accepts, the writer must write.

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "models/field_table.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  const std::string text = fuzz::text_of(data, size);
  fuzz::expect_input_error([&] {
    const FieldTable table = FieldTable::parse_csv(text, "fuzz.csv");
    (void)table.to_csv();
  });
  return 0;
}
