#pragma once
// The trajectory predictor the controller uses: classical RK4 on each object's ray.
//
// Under one orientation an object never leaves its ray from s (models/object_dynamics.h: Ray), so
// the state is (r, v) with dr/dt = v, dv/dt = xi1 v + xi2 b1 (e^{b2 r} - e^{b3 r}) + xi3 (eqs.
// 3, 8, 9), the ray's eq. (3) profile fixed for the whole segment. Objects are integrated side by
// side in blocks of 32 lanes with branch-free, vectorised arithmetic; each lane keeps its own
// clock, so its result does not depend on the other lanes. Each constant-orientation segment, and
// each interval between requested sample times, is cut per object into equal steps no longer than
// max_step_s and, within ~15 cm of s where eq. (3) is steep, no longer than rate_factor / rate.
//
// Stop event, exact: after a step in which a moving object's v fell below 0, the crossing is
// located on the step's cubic Hermite interpolant of v (values and eq. (8) slopes at both ends;
// first falling zero, safeguarded Newton), r comes from the cubic Hermite of r (slopes v) at that
// time, v is set to exactly 0, and the object rests for the rest of the segment when the drive
// there is <= 0. A rest never carries a negative speed.
//
// Step sizes: chosen by measurement against CvodePredictor (docs/dynamics.md): max end-position
// error 0.02 mm over the Appendix D envelope, <= 0.35 mm near s and under schedules.

#include <string>

#include "models/trajectory_predictor.h"

namespace airtwin {

class FastPredictor final : public TrajectoryPredictor {
 public:
  /// Default largest step (s) and step-rate factor; see docs/dynamics.md for the measurements.
  static constexpr double kDefaultMaxStep = 0.1;
  static constexpr double kDefaultRateFactor = 0.5;

  struct Options {
    double max_step_s = kDefaultMaxStep;  ///< largest RK4 step, s
    /// Each object's step is also at most rate_factor / rho, rho (1/s) the spectral radius of
    /// the (r, v) system's Jacobian at the start of its previous step: small steps only where
    /// eq. (3) is steep (within a few cm of s), for the objects that are there.
    double rate_factor = kDefaultRateFactor;
  };

  FastPredictor() = default;
  /// Throws InputError unless max_step_s is finite and in (0, 10] s and rate_factor is finite
  /// and > 0.
  explicit FastPredictor(const Options& options);

  std::string name() const override { return "fast"; }
  const Options& options() const { return options_; }

 protected:
  void advance(const Segment& segment, std::span<const ObjectDynamics> dynamics,
               std::span<ObjectState> state, std::span<double> rest_since_s) const override;

 private:
  Options options_;
};

}  // namespace airtwin
