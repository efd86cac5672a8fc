#pragma once
// Calibrating the twin's drag and friction so that the paper's identification, run on data the
// twin collects, returns the paper's coefficients (section IV-B/C).
//
// The twin's object physics is written in the form of eq. (8) (sim/scene_spec.h): drag rate
// c/m = -x1, air gain k = x2 / (-x1), kinetic friction mu_k = -x3 / g, for a "physics" triple
// x = (x1, x2, x3). Identification on twin data does not return x itself: turbulence, the soft
// contacts (the disc rocks while it slides), static friction and the pressure push all bend what
// SINDy sees. Calibration is a fixed-point iteration on x, each coefficient corrected by the
// ratio of the target to what was identified:
//     x_j <- x_j * target_j / identified_j      (j = 1, 2, 3; the signs never change)
// with a full Appendix D collection (sim/collection.h) and identification
// (models/identification.h) per iteration. The map from x to the identified triple is close to a
// per-coefficient scaling, so the iteration settles in 2-4 rounds.

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "models/identification.h"
#include "models/object_dynamics.h"
#include "sim/collection.h"

namespace airtwin {

struct DynamicsCalibrationOptions {
  CollectionOptions collection;          ///< its object and twin parameters are the start
  IdentificationOptions identification;  ///< robust E-SINDy by default
  ObjectDynamics target;                 ///< what identification should return (the paper's)
  int iterations = 4;
};

struct DynamicsCalibrationStep {
  ObjectDynamics physics;     ///< the twin's physics triple of this round
  ObjectDynamics identified;  ///< eq. (8) identified from this round's data
  double r2 = 0.0;
  double end_position_mape_pct = 0.0;
  std::map<double, double> mape_by_tilt_pct;
  double worst_relative_error = 0.0;  ///< max_j |identified_j / target_j - 1|
};

struct DynamicsCalibration {
  ObjectDynamics physics;  ///< the round with the smallest worst relative error
  std::vector<DynamicsCalibrationStep> history;
  /// Empty, or why the iteration stopped early (an identification without the form of eq. (8)
  /// or with a wrong sign: nothing to correct from). The best round so far is kept.
  std::string stopped;
};

/// Sets the drag rate, air gain and kinetic friction of `p` from a physics triple (the inverse of
/// ObjectTypeParameters::dynamics()).
void set_physics(const ObjectDynamics& physics, ObjectTypeParameters* p,
                 double gravity_mps2 = 9.81);

/// Runs the iteration. Throws InputError when the very first identification does not have the
/// form of eq. (8) with the target's signs (nothing to start from); a later such round ends the
/// iteration (see DynamicsCalibration::stopped). `progress(step, round, rounds)` after each
/// round (1-based).
DynamicsCalibration calibrate_dynamics(
    const DynamicsCalibrationOptions& options, const AirFieldModel& field,
    const std::function<void(const DynamicsCalibrationStep&, int, int)>& progress = {});

/// Repeatability as the paper measured it (section IV-B): the same trial run `repeats` times
/// with different twin seeds (turbulence) and the object placed within `placement_m` of the same
/// start (the paper: within 5 mm), the mean over repeats 2..n of |end_i - end_1| in percent of
/// the first run's travel |end_1 - start|. nullopt when the first run moved less than 1 cm.
std::optional<double> repeatability_mape_pct(const CollectionTrial& trial,
                                             const CollectionOptions& options,
                                             const AirFieldModel& field, int repeats,
                                             double placement_m = 0.005);

}  // namespace airtwin
