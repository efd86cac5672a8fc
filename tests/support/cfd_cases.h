#pragma once
// Small CFD cases written from a formula, in the shipped format ("airtwin-cfd-floor 1",
// docs/data_formats.md), for the tests of the CFD reader and of the twin in CFD air.

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace airtwin::testing {

/// The fields of a synthetic case at (x, y >= 0, z) of the case frame: ux, uy, uz, k, epsilon, p.
using CfdSynthetic = std::function<std::array<double, 6>(double, double, double)>;

/// The heights (m) of every synthetic case: 5, 15 and 25 mm.
inline const std::vector<double> kCfdTestHeights = {0.005, 0.015, 0.025};

/// Writes case `name` (header and float32 data) into `dir`: x in [-1, 1] m, y in [0, 1] m, 0.1 m
/// pitch, the heights above, ambient k 1e-3 m^2/s^2 and epsilon 2e-3 m^2/s^3. Returns the header.
std::string write_cfd_case(const std::string& dir, const std::string& name, double tilt_deg,
                           double s_x, const CfdSynthetic& fn, bool held_out = false);

}  // namespace airtwin::testing
