#pragma once
// Appendix D collection through the camera, as the rig recorded it: each trial runs by the
// protocol of sim/collection.h (same plan, same twin, same frames), but its object's positions
// are what the twin's top camera shows (renders/frame_renderer.h, with optional sensor noise and
// blur) after detection (vision/object_detector.h: Hough circles for tracers, blobs for cotton),
// back-projection through a CALIBRATED camera model (vision/calibrated_camera.h) and tracking
// (vision/tracker.h). The twin's truth of the same frames is kept beside them, to measure the
// error the camera adds; it never feeds the recorded positions.
//
// The trial's object is the track of the first recorded frame's detection nearest the planned
// start (the operator knows where the object was placed). A trial is kept only if that track has
// a detection in every recorded frame; otherwise it is dropped, as a rig drops a trial whose
// object it did not follow, and counted by reason (not found at the start, lost, left the view).
//
// Determinism: each trial renders with its own renderer, detector and tracker, its sensor noise
// seeded by the trial's twin seed and the frame's index, so a trial's data depend on the seed and
// its index only, never on the thread count.

#include <cstdint>
#include <functional>
#include <vector>

#include "models/air_field.h"
#include "models/trajectory_data.h"
#include "sim/collection.h"
#include "vision/calibrated_camera.h"

namespace airtwin {

struct CameraCollectionOptions {
  CollectionOptions collection;   ///< the protocol and the twin (threads: trials in parallel)
  double noise_sigma_grey = 0.0;  ///< sensor noise of the rendered frames (grey levels)
  double blur_sigma_px = 0.0;     ///< optical blur (px)
  /// Fastest the object is expected to move (m/s): the tracker's gate per frame. One object per
  /// trial, so the gate can be wide: tracers reach ~3 m/s near s.
  double max_speed_mps = 4.0;
  /// The object's track is the first frame's detection nearest the planned start, within this
  /// (m): the object may have settled a little under the idle jet.
  double start_radius_m = 0.10;

  /// Throws FieldError naming the field ("camera_collection.noise_sigma_grey") when a value is
  /// out of range, and the collection's own.
  void validate() const;
};

/// Why a trial was kept or dropped.
enum class CameraTrialOutcome {
  kKept = 0,
  kNotFoundAtStart = 1,  ///< no detection near the planned start in the first frame
  kLost = 2,             ///< the object's track missed a frame inside the view
  kLeftView = 3,         ///< the object's track missed a frame at the image's edge
};

/// "kept", "not found at the start", "lost", "left the view".
const char* camera_trial_outcome_name(CameraTrialOutcome outcome);

struct CameraTrialResult {
  CameraTrialOutcome outcome = CameraTrialOutcome::kKept;
  Trajectory camera;  ///< the camera's positions (m); every frame when kept, else up to the loss
  Trajectory truth;   ///< the twin's positions of the same frames (m)
};

/// Runs one trial through the camera. Throws SimulationError when the twin fails, RenderError
/// when OSMesa fails, InputError for options the renderer or detector reject.
CameraTrialResult run_camera_collection_trial(const CollectionTrial& trial,
                                              const CameraCollectionOptions& options,
                                              const AirFieldModel& field,
                                              const CalibratedCamera& camera);

struct CameraCollectionResult {
  TrajectorySet camera;  ///< the kept trials, plan order, id = trial index
  TrajectorySet truth;   ///< the twin's positions of the same trials and frames
  int planned = 0;
  int kept = 0;
  int not_found_at_start = 0;
  int lost = 0;
  int left_view = 0;
  /// Camera against truth over every position of the kept trials (m).
  int64_t positions = 0;
  double rms_error_m = 0.0;
  double max_error_m = 0.0;

  int dropped() const { return not_found_at_start + lost + left_view; }
};

/// Runs the trials of `plan` (in parallel when options.collection.threads != 1) and tallies them.
/// `progress(done, total)` (optional) is called after each finished trial, one thread at a time.
CameraCollectionResult run_camera_collection(const std::vector<CollectionTrial>& plan,
                                             const CameraCollectionOptions& options,
                                             const AirFieldModel& field,
                                             const CalibratedCamera& camera,
                                             const std::function<void(int, int)>& progress = {});

/// The same for the protocol's plan (plan_collection(options.collection)).
CameraCollectionResult run_camera_collection(const CameraCollectionOptions& options,
                                             const AirFieldModel& field,
                                             const CalibratedCamera& camera,
                                             const std::function<void(int, int)>& progress = {});

}  // namespace airtwin
