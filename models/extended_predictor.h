#pragma once
// Predicting one object over a window of time under the extended model: eqs. (8)-(9) in vector
// form, with the nozzle's response (models/nozzle_response.h) and the catalogue's extensions
// (models/model_extensions.h).
//
// With v the object's velocity (m/s), u the air velocity at its position (m/s) and xi its eq. (8)
// coefficients, while the object moves
//   dv/dt = xi1 v + xi2 u + xi3 v/|v|                       (eq. 8: friction opposes motion)
//         + C |u - v| (u - v)                               (quadratic_drag)
//         + a_p(r) e_r                                      (pressure_gradient, outward from s)
//         + g sin(angle) d                                  (floor_slope, downhill unit d)
// with u = field_scale R(deflection) u_eq3(p; orientation the field follows), and that
// orientation = NozzleTimeline::effective(t, tau) + nozzle_offset; with the transport lag the
// object at p feels instead the newest such orientation o(t') whose air has spread to it from
// its stagnation point s(t'): t - t' >= min(pace |p - s(t')|, kMaxTransportLagS) (each object
// its own orientation while a re-aim's front spreads). The air lifts the object (air_lift): its
// friction is |xi3| max(0, 1 - k |u - v|^2), static and kinetic alike. With linearised_drag
// (share s of the friction, c = -xi1 > 0, xi3 < 0) the air's part xi1 v + xi2 u = c w,
// w = (xi2 / c) u - v, is read as the tangent at |w| = w0 = 2 s |xi3| / c of a quadratic drag: it
// becomes (c |w| - s |xi3|) w/|w| for |w| >= w0 and (c / 2 w0) |w| w below, and the friction is
// (1 - s) |xi3|. An object at rest starts when the pull without friction exceeds stiction-ratio
// times that friction; a moving object stops when friction would reverse it. Under one
// orientation and with every extension off, the velocity stays radial from s and this is exactly
// eqs. (8)-(9) (tests/models/extended_predictor_test.cc checks it against the CVODE reference).
//
// Integration: semi-implicit Euler with Coulomb friction at a fixed step (1 ms by default; the
// position error against eqs. (8)-(9) is ~1 mm over 2 s), deterministic, no allocation per step.
// Thread safety: immutable after construction, predict() is const.

#include <Eigen/Core>
#include <span>
#include <vector>

#include "models/air_field.h"
#include "models/model_extensions.h"
#include "models/nozzle_response.h"
#include "models/object_dynamics.h"

namespace airtwin {

/// The state an object starts a window in.
struct WindowStart {
  double t_s = 0.0;                               ///< window start (s, the timeline's clock)
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();  ///< m
  Eigen::Vector2d v_W = Eigen::Vector2d::Zero();  ///< m/s
};

/// The orientations the air follows over one prediction's steps without the transport lag, each
/// with its field seen along rays: what predict() works out at every step while the servos turn.
/// They are the same for every prediction of one window (timeline, start, step) under extensions
/// with the same response delay and nozzle offset, so a caller that predicts a window many times
/// (the discrepancy analysis's fits) has them worked out once (ExtendedPredictor::track).
class OrientationTrack {
 public:
  /// Whether predict() with these arguments can read its orientations here.
  bool serves(const ModelExtensions& ext, const NozzleTimeline& timeline, double t0_s,
              double step_s) const;
  /// The memory it holds (bytes).
  size_t bytes() const;

 private:
  friend class ExtendedPredictor;
  const AirFieldModel* field_ = nullptr;
  const NozzleTimeline* timeline_ = nullptr;
  double t0_s_ = 0.0, step_s_ = 0.0;
  double extra_delay_s_ = 0.0, pan_offset_rad_ = 0.0, tilt_offset_rad_ = 0.0;
  std::vector<unsigned> run_of_step_;  // step j (at t0 + j steps, summed): its run
  std::vector<OrientedRays> runs_;     // runs of one orientation, in time order
};

class ExtendedPredictor {
 public:
  /// `field` must outlive the predictor. Throws InputError unless step_s is finite and in
  /// (0, 0.05] s.
  explicit ExtendedPredictor(const AirFieldModel& field, double step_s = 1e-3);

  /// Positions of the object at `times_s` (absolute, non-decreasing, none before start.t_s):
  /// `positions` gets one entry per time. `ext` as the object's type feels them
  /// (ModelExtensions::for_type). Throws InputError when the inputs are not finite, the times are
  /// not ordered, the extensions are invalid or hold a type's own effects.
  /// `track`, when given and serving these arguments (OrientationTrack::serves), supplies the
  /// orientations: the same positions, sooner.
  void predict(const ObjectDynamics& xi, const ModelExtensions& ext, const NozzleTimeline& timeline,
               const WindowStart& start, std::span<const double> times_s,
               std::vector<Eigen::Vector2d>* positions,
               const OrientationTrack* track = nullptr) const;

  /// The orientations predict() follows from t0_s up to t_end_s under `ext`'s response delay and
  /// nozzle offset (its other extensions play no part). Throws InputError when `ext` has the
  /// transport lag (each point then feels its own orientation) or the times are not finite.
  OrientationTrack track(const ModelExtensions& ext, const NozzleTimeline& timeline, double t0_s,
                         double t_end_s) const;

  /// The end positions at `t_end_s` of several objects that start together (every start at the
  /// same t_s) under one timeline: each object's result is the same as predict() with the one
  /// sample time t_end_s would give, at a fraction of the cost (the field is rebuilt once per
  /// orientation change for all objects). `objects_ext` gives each object its type's per_type
  /// effects (ModelExtensions::object_for), in place of ext.object and ext.object_by_type; empty:
  /// ext.object for all. `ends` has one entry per start. Throws InputError when sizes differ, the
  /// starts differ in time, an input is not finite, or `objects_ext` is empty and `ext` holds a
  /// type's own effects.
  void predict_ends(std::span<const ObjectDynamics> xi, const ModelExtensions& ext,
                    std::span<const ObjectExtensions> objects_ext, const NozzleTimeline& timeline,
                    std::span<const WindowStart> starts, double t_end_s,
                    std::span<Eigen::Vector2d> ends) const;

  /// The orientation the air follows at t under `ext` (offset added, tilt kept inside the field
  /// model's range).
  NozzleOrientation field_orientation(const ModelExtensions& ext, const NozzleTimeline& timeline,
                                      double t_s) const;

  const AirFieldModel& field() const { return field_; }
  double step_s() const { return step_; }

 private:
  const AirFieldModel& field_;
  double step_;
  double max_tilt_rad_;
};

}  // namespace airtwin
