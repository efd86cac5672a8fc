// Fuzz target: target.yaml, the checkerboard and its reference pose that `calibrate` reads from a
// calibration folder (vision/camera_calibration.h). The reader takes a path only, so the input is
// written to target.yaml in the scratch folder. A target the reader accepts must place its
// corners.

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "vision/camera_calibration.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  static const std::filesystem::path target = fuzz::scratch_dir() / "target.yaml";
  fuzz::write_file(target, fuzz::text_of(data, size));
  fuzz::expect_input_error([&] {
    const CalibrationTarget t = CalibrationTarget::read(target.string());
    (void)t.reference_corner_W(0, 0);
    (void)t.reference_corner_W(t.inner_corners_cols - 1, t.inner_corners_rows - 1);
  });
  return 0;
}
