// Fuzz target: the speed-series CSV of `identify --series` (models/speed_series.h).

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "models/speed_series.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  const std::string text = fuzz::text_of(data, size);
  fuzz::expect_input_error([&] { (void)parse_speed_series_csv(text, "fuzz.csv"); });
  return 0;
}
