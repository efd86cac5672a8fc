// Fuzz target: the calibrated camera file calib.yaml of detect and run --vision
// (vision/calibrated_camera.h). The reader takes a path only (cv::FileStorage), so the input is
// written to calib.yaml in the scratch folder. A camera the reader accepts must map points.

#include <cstddef>
#include <cstdint>

#include <Eigen/Core>

#include "fuzz/fuzz_support.h"
#include "vision/calibrated_camera.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  static const std::filesystem::path calib = fuzz::scratch_dir() / "calib.yaml";
  fuzz::write_file(calib, fuzz::text_of(data, size));
  fuzz::expect_input_error([&] {
    const CalibratedCamera camera = CalibratedCamera::read(calib.string());
    (void)camera.centre_W();
    (void)camera.project(Eigen::Vector3d(0.1, -0.2, 0.0));
    (void)camera.point_at_height(Eigen::Vector2d(0.5 * camera.width_px, 10.0), 0.01);
  });
  return 0;
}
