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
#include <vector>

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
  /// Closest two objects' centres can be (m): a tracer's visible cap is 2.8 cm across, a wad's
  /// 4.1 cm, so touching objects are >= ~3.4 cm apart. Of two tracks closer than this the newer
  /// is the same object seen twice (a stretched wad peeled into a wad and a "tracer") and is not
  /// reported; 0 reports every track.
  double min_separation_m = 0.025;
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
  /// Tracks withheld from observations as duplicates of an older one (min_separation_m), summed
  /// over the observations.
  int64_t duplicates() const;
  /// The detections of every processed frame as `detect` writes them (docs/data_formats.md,
  /// "Detections"): `frame` the index of the processed frame (0, 1, ... at rate_hz), `t` its time
  /// (s). The tracker ends a track after max(2, rate_hz rounded) missed processed frames.
  const std::string& detections_csv() const;
  /// Frames processed and the mean wall-clock ms per frame (render + detection + tracking).
  int64_t frames_processed() const;
  double mean_frame_ms() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// What the controller is told of the tracker's tracks at time t_s (the last processed frame):
/// each track detected within report_missing_s, at its predicted position, as `v<id>` with its
/// kind and velocity; of tracks closer than min_separation_m the oldest only (the others are
/// counted in `duplicates`).
struct TrackReport {
  std::vector<ObservedObject> objects;
  int64_t duplicates = 0;
};
TrackReport report_tracks(const std::vector<Track>& tracks, double t_s,
                          const VisionPerceptionOptions& options);

/// Calibrates the twin's top camera the way a user calibrates the rig's: renders views of the
/// checkerboard target into `dir` (renders/calibration_target.h) and runs the calibration on that
/// folder. Returns the calibrated model (the caller may save it with CalibratedCamera::write).
CalibratedCamera calibrate_twin_camera(const std::string& dir, const SceneParameters& params,
                                       uint64_t seed, double noise_sigma_grey = 0.0,
                                       double blur_sigma_px = 0.0);

}  // namespace airtwin
