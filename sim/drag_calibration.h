#pragma once
// Calibrating the physical drag (DragLaw::kPhysical) by the paper's protocol: collect Appendix D
// data in the twin (sim/collection.h), identify them as the paper did (models/identification.h),
// and search the object type's physical parameters (sim/object_physics.h: C_D, kinetic friction,
// static/kinetic ratio, mass...) within windows from the literature for the point whose
// identified eq. (8) coefficients come closest to the target (the paper's).
//
// Unlike the eq. (8) physics (sim/dynamics_calibration.h), no parameter maps onto one coefficient:
// C_D scales both drag terms, friction the constant, and the ratio xi2 / -xi1 follows from the
// physics rather than being set. So the search is a grid over the windows, refined around the
// best point (each refinement halves the spacing), and every point is kept for the record.
//
// Each point is identified twice: with the terms of eq. (8) fixed (1, v, vair), which always
// gives the three coefficients the distance to the target is measured on, and with the options
// as given (the paper's: the full cubic library), whose selected terms are reported beside it -
// the paper's identification found exactly eq. (8)'s on its rig.

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "models/identification.h"
#include "models/object_dynamics.h"
#include "models/trajectory_replay.h"
#include "sim/collection.h"
#include "sim/object_physics.h"

namespace airtwin {

/// One searched parameter: its window (typed units, sim/object_physics.h) and grid points.
struct DragCalibrationAxis {
  ObjectPhysicsKey key = ObjectPhysicsKey::kDragCoefficient;
  double min = 0.0, max = 0.0;
  int points = 3;  ///< >= 2 (1 when min == max: the parameter is fixed)
};

struct DragCalibrationOptions {
  /// Its object type must use the physical drag law (ObjectTypeParameters::use_physical_drag).
  CollectionOptions collection;
  IdentificationOptions identification;  ///< the paper's defaults: full cubic library
  ObjectDynamics target;                 ///< what identification should return
  std::vector<DragCalibrationAxis> axes;
  int refinements = 1;  ///< grids around the best point, each at half the spacing

  /// FieldError naming the field ("calibration.axes", and in its detail the axis) for an unusable
  /// value.
  void validate() const;
};

/// One evaluated point.
struct DragCalibrationPoint {
  std::vector<double> values;  ///< per axis, typed units
  ObjectDynamics eq8_form;     ///< identified with the terms 1, v, vair fixed
  double r2 = 0.0;             ///< of that fit
  double end_position_mape_pct = 0.0;
  std::map<double, double> mape_by_tilt_pct;
  /// By tilt and placement sector around s (models/trajectory_replay.h).
  std::map<double, std::array<SectorFigures, kPlacementSectors>> by_sector;
  double worst_relative_error = 0.0;  ///< max_j |eq8_form_j / target_j - 1|
  std::string full_library_terms;     ///< the terms the given options selected, "v,v^2,..."
  bool full_library_is_eq8 = false;   ///< they are exactly 1, v, vair
};

struct DragCalibration {
  std::vector<DragCalibrationPoint> points;  ///< in evaluation order
  size_t best = 0;                           ///< the smallest worst relative error
  /// The best point's repeatability as the paper measured it (sim/dynamics_calibration.h,
  /// repeatability_mape_pct): 8 trials at the first tilt, 6 runs each; NaN when none moved.
  double best_repeatability_pct = 0.0;
};

/// The active terms of a model, comma-separated in library order ("1,v,vair").
std::string active_terms(const IdentifiedModel& model);

/// Evaluates one point: the collection with `values` set on the object type, and both fits.
DragCalibrationPoint evaluate_drag_point(const DragCalibrationOptions& options,
                                         const std::vector<double>& values,
                                         const AirFieldModel& field);

/// Runs the search. `progress(point, index)` after each point (0-based). Throws FieldError for bad
/// options and InputError when a collection cannot be identified at all.
DragCalibration calibrate_drag(
    const DragCalibrationOptions& options, const AirFieldModel& field,
    const std::function<void(const DragCalibrationPoint&, size_t)>& progress = {});

/// The paper's repeatability of the object type with `values` set (sim/dynamics_calibration.h,
/// repeatability_mape_pct): 8 placements at the collection's first tilt, six runs each, the mean;
/// NaN when none moved.
double drag_point_repeatability_pct(const DragCalibrationOptions& options,
                                    const std::vector<double>& values, const AirFieldModel& field);

/// One point checked on a collection the calibration did not see: the whole protocol (Appendix D,
/// both fits, the repeatability) at another seed. One collection's figures scatter by more than
/// sets of parameters differ (docs/twin.md, "The tracer's two sets over 30 collections"), so a
/// calibration is judged on several.
struct DragCalibrationCheck {
  std::uint64_t seed = 0;
  DragCalibrationPoint point;
  double repeatability_pct = 0.0;  ///< NaN when none moved
  /// eq. (8)'s air term survived the identification's threshold: without it the identified
  /// model says that no air moves the object.
  bool air_term_kept() const { return point.eq8_form.xi2 > 0.0; }
};

/// Checks the point `values` on the collections of `seeds`, in order, each evaluated as
/// calibrate_drag evaluates its points. FieldError ("calibration.held_out_seeds") when `seeds` is
/// empty, repeats a seed or holds the calibration's own (options.collection.seed).
/// `progress(check, index)` after each.
std::vector<DragCalibrationCheck> check_drag_point(
    const DragCalibrationOptions& options, const std::vector<double>& values,
    const std::vector<std::uint64_t>& seeds, const AirFieldModel& field,
    const std::function<void(const DragCalibrationCheck&, size_t)>& progress = {});

/// The median and range of one figure over checks; n 0 (and NaN) when none had it.
struct DragCheckSpread {
  size_t n = 0;
  double median = NAN, min = NAN, max = NAN;
};

/// What held-out checks say together. The coefficients' error and the end MAPE are of the checks
/// that kept the air term (without it the identified model is another one, counted apart); the
/// repeatability of those where an object moved.
struct DragCheckSummary {
  int air_term_lost = 0;
  DragCheckSpread worst_relative_error;
  std::map<double, DragCheckSpread> mape_by_tilt_pct;  ///< by tilt (deg)
  /// By tilt and placement sector: the spread of the sector's MAPE over the checks whose
  /// collection placed objects there.
  std::map<double, std::array<DragCheckSpread, kPlacementSectors>> mape_by_tilt_sector_pct;
  DragCheckSpread repeatability_pct;
  int full_library_is_eq8 = 0;  ///< checks whose full library selected exactly 1, v, vair
};

DragCheckSummary summarize_checks(const std::vector<DragCalibrationCheck>& checks);

}  // namespace airtwin
