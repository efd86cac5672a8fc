// Fuzz target: the trajectory CSV (models/trajectory_data.h), which identify, discrepancy and the
// run logs use. What the reader accepts, the writer must write.

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "models/trajectory_data.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  const std::string text = fuzz::text_of(data, size);
  fuzz::expect_input_error([&] {
    const TrajectorySet set = parse_trajectory_csv(text, "fuzz.csv");
    (void)trajectory_csv(set);
  });
  return 0;
}
