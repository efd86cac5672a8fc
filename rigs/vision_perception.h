#pragma once
// `--vision`: the controller sees the twin through the detection pipeline, as it would see the
// rig. Camera frames are rendered from the twin (renders/frame_renderer.h, optional sensor noise
// and blur), objects are detected and classified (vision/object_detector.h) and positioned on the
// floor through a CALIBRATED camera model (vision/camera_calibration.h, computed from rendered
// frames of a checkerboard, never from the renderer's ground truth), and tracked across frames
// (vision/tracker.h), which gives the ids and velocities the controller is told.
//
// Frames are processed at `rate_hz` of simulated time (default 10 Hz, every 4th camera frame:
// the controller decides every ~1.8 s and needs a velocity at that moment; 40 Hz would triple
// the run's cost for nothing). The tracker's gate is scaled to that rate.

#include <cstdint>
#include <memory>
#include <string>

#include "rigs/twin_rig.h"
#include "vision/calibrated_camera.h"
#include "vision/tracker.h"

namespace airtwin {

struct VisionPerceptionOptions {
  double rate_hz = 10.0;          ///< detection rate (simulated time), divides 40 Hz
  double noise_sigma_grey = 0.0;  ///< sensor noise of the rendered frames
  double blur_sigma_px = 0.0;     ///< optical blur
  uint64_t seed = 0;              ///< of the sensor noise
  /// Fastest an object is expected to move (m/s): the tracker's gate per processed frame.
  double max_speed_mps = 2.0;
  /// Tracks not detected for longer than this (s) are not reported (the controller keeps their
  /// last position anyway).
  double report_missing_s = 0.5;
};

class VisionPerception final : public Perception {
 public:
  /// `camera`: the calibrated model of the twin's top camera. Throws InputError for bad options.
  VisionPerception(const CalibratedCamera& camera, const VisionPerceptionOptions& options = {});
  ~VisionPerception() override;

  void on_frame(const Twin& twin, int64_t frame_index) override;
  Observation observe(const Twin& twin) override;

  /// The tracker's totals (frames, detections, new tracks, missed, merged, lost, left view).
  const TrackerCounters& counters() const;
  /// Frames processed and the mean wall-clock ms per frame (render + detection + tracking).
  int64_t frames_processed() const;
  double mean_frame_ms() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Calibrates the twin's top camera the way a user calibrates the rig's: renders views of the
/// checkerboard target into `dir` (renders/calibration_target.h) and runs the calibration on that
/// folder. Returns the calibrated model (the caller may save it with CalibratedCamera::write).
CalibratedCamera calibrate_twin_camera(const std::string& dir, const SceneParameters& params,
                                       uint64_t seed, double noise_sigma_grey = 0.0,
                                       double blur_sigma_px = 0.0);

}  // namespace airtwin
