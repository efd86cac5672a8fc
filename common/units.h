#pragma once
// SI inside; degrees only at the edges people type or read. These are the only conversions.

#include <numbers>

namespace airtwin {

inline constexpr double kPi = std::numbers::pi;

constexpr double deg_to_rad(double deg) { return deg * (kPi / 180.0); }
constexpr double rad_to_deg(double rad) { return rad * (180.0 / kPi); }

}  // namespace airtwin
