#pragma once
// The reference trajectory predictor: SUNDIALS CVODE (v6) on the planar form of eqs. (8)-(9),
// state (x, y, v) per object, the air speed from the field model at the current position. Adams
// (variable order 1-12) with the fixed-point nonlinear solver, the closest CVODE match to MATLAB's
// ode113 that the paper used. Tight default tolerances (rtol 1e-10, atol 1e-12 in m and m/s).
//
// It does not use the ray reduction that FastPredictor relies on, so comparing the two checks that
// reduction as well as the fast integrator.
//
// Stop event: CVODE's root finding (CVodeRootInit) on g = v, falling crossings only. At the root v
// is set to exactly 0; the object rests for the rest of the segment when the drive there is <= 0,
// otherwise (a tangency, v touching 0 where the drive vanishes) it is restarted from v = 0.
//
// Every SUNDIALS return flag is checked; a failure throws IntegrationError with the call, its flag
// name, SUNDIALS' own message, the time and the object. Nothing is printed, nothing aborts.

#include <string>

#include "models/trajectory_predictor.h"

namespace airtwin {

class CvodePredictor final : public TrajectoryPredictor {
 public:
  struct Options {
    double rtol = 1e-10;          ///< relative tolerance
    double atol = 1e-12;          ///< absolute tolerance, m for the position and m/s for the speed
    long max_num_steps = 100000;  ///< per output interval (CVodeSetMaxNumSteps)
  };

  CvodePredictor() = default;
  /// Throws InputError when a tolerance is not finite and > 0 or max_num_steps < 1.
  explicit CvodePredictor(const Options& options);

  std::string name() const override { return "cvode"; }
  const Options& options() const { return options_; }

 protected:
  void advance(const Segment& segment, std::span<const ObjectDynamics> dynamics,
               std::span<ObjectState> state, std::span<double> rest_since_s) const override;

 private:
  Options options_;
};

}  // namespace airtwin
