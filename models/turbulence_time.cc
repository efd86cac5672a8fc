#include "models/turbulence_time.h"

#include <cmath>

namespace airtwin {
namespace {
// L11 / (k^1.5 / epsilon) at high Reynolds number (Pope 2000, Fig. 6.22).
constexpr double kL11 = 0.43;
}  // namespace

double integral_length_m(double k, double epsilon) { return kL11 * std::pow(k, 1.5) / epsilon; }

double swept_integral_time_s(double lagrangian_time_s, double sweep_speed_mps, double k,
                             double epsilon) {
  return 1.0 / (1.0 / lagrangian_time_s + sweep_speed_mps / integral_length_m(k, epsilon));
}

}  // namespace airtwin
