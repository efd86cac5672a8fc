// Fuzz target: the times file of `detect --times` (vision/frame_source.h). The reader takes a path
// only, so the input is written to times.csv in the scratch folder.

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "vision/frame_source.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  static const std::filesystem::path times = fuzz::scratch_dir() / "times.csv";
  fuzz::write_file(times, fuzz::text_of(data, size));
  fuzz::expect_input_error([&] { (void)read_frame_times(times.string()); });
  return 0;
}
