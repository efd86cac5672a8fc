#pragma once
// Synthetic measured data for the identification tests: objects released at rest 20-58 cm from s
// (Appendix D), recorded 2 s at 40 Hz, integrated with RK4 at 0.25 ms along their ray, written
// independently of the library's predictors (a second implementation of eqs. 8-9 under a fixed
// orientation). Tilts alternate 0 / 22.5 deg; pan and direction are drawn from the seed.

#include <cstdint>
#include <string>

#include "models/air_field.h"
#include "models/trajectory_data.h"

namespace airtwin::testing {

/// n trajectories of `object` with eq. (8) coefficients (xi1, xi2, xi3), 81 frames each.
TrajectorySet make_ray_trajectories(const AirFieldModel& model, double xi1, double xi2, double xi3,
                                    int n, std::uint64_t seed, const std::string& object);

/// The same kind of motion as one speed-series CSV (`t,v,vair`): n objects one after the other,
/// each starting at rest, with multiplicative Gaussian noise of relative size `noise` on v.
std::string make_speed_series_csv(const AirFieldModel& model, double xi1, double xi2, double xi3,
                                  int n, std::uint64_t seed, double noise);

}  // namespace airtwin::testing
