#include "models/air_field.h"

#include <algorithm>
#include <cmath>

#include "common/errors.h"
#include "common/units.h"
#include "models/makima.h"

namespace airtwin {
namespace {

constexpr double kBinsPerRad = FieldTable::kAlphaBins / (2.0 * kPi);

double coefficient(const FieldCoefficients& c, int k) { return k == 0 ? c.b1 : k == 1 ? c.b2 : c.b3; }

}  // namespace

AirFieldModel::AirFieldModel(NozzleGeometry geometry, FieldTable table)
    : geometry_(geometry), table_(std::move(table)) {
  geometry_.validate();
  // Makima slopes depend only on the node values, so they are computed once per (alpha, b_k).
  const size_t n = table_.n_tilts();
  slopes_by_tilt_.resize(n);
  std::vector<double> y(n);
  for (int a = 0; a < FieldTable::kAlphaBins; ++a) {
    for (int k = 0; k < 3; ++k) {
      for (size_t i = 0; i < n; ++i) y[i] = coefficient(table_.at(i, a), k);
      const std::vector<double> d = makima_slopes(table_.tilts_rad(), y);
      for (size_t i = 0; i < n; ++i) slopes_by_tilt_[i][a][k] = d[i];
    }
  }
}

AirFieldModel AirFieldModel::with_default_table() {
  return AirFieldModel(NozzleGeometry{}, FieldTable::default_table());
}

OrientedField AirFieldModel::at(const NozzleOrientation& o) const {
  if (!(std::isfinite(o.pan_rad) && std::isfinite(o.tilt_rad) && o.tilt_rad >= 0 &&
        o.tilt_rad < kPi / 2)) {
    throw InputError("nozzle orientation: pan must be finite and tilt in [0, 90) deg, got pan " +
                     std::to_string(rad_to_deg(o.pan_rad)) + " deg, tilt " +
                     std::to_string(rad_to_deg(o.tilt_rad)) + " deg");
  }
  OrientedField f;
  f.orientation_ = o;
  // (i) eqs. (1), (2)
  f.c_W_ = projection_point(geometry_, o);
  f.s_W_ = stagnation_point(geometry_, o);

  // Makima in tilt, clamped to the fitted range: one set of Hermite weights serves all profiles.
  const std::vector<double>& tilts = table_.tilts_rad();
  size_t i;
  double t;
  locate_interval(tilts, o.tilt_rad, &i, &t);
  f.coefficient_tilt_rad_ = std::clamp(o.tilt_rad, tilts.front(), tilts.back());
  const HermiteWeights w = hermite_weights(t, tilts[i + 1] - tilts[i]);
  for (int a = 0; a < FieldTable::kAlphaBins; ++a) {
    const FieldCoefficients& y0 = table_.at(i, a);
    const FieldCoefficients& y1 = table_.at(i + 1, a);
    const auto& d0 = slopes_by_tilt_[i][a];
    const auto& d1 = slopes_by_tilt_[i + 1][a];
    f.ring_[a].b1 = w.h00 * y0.b1 + w.h10 * d0[0] + w.h01 * y1.b1 + w.h11 * d1[0];
    f.ring_[a].b2 = w.h00 * y0.b2 + w.h10 * d0[1] + w.h01 * y1.b2 + w.h11 * d1[1];
    f.ring_[a].b3 = w.h00 * y0.b3 + w.h10 * d0[2] + w.h01 * y1.b3 + w.h11 * d1[2];
  }
  f.ring_[FieldTable::kAlphaBins] = f.ring_[0];
  return f;
}

FieldCoefficients OrientedField::coefficients(double alpha_rad) const {
  // Linear interpolation between the two neighbouring 1-degree profiles, wrapping at 360.
  double u = alpha_rad * kBinsPerRad;
  u -= FieldTable::kAlphaBins * std::floor(u / FieldTable::kAlphaBins);
  int k = static_cast<int>(u);
  if (k >= FieldTable::kAlphaBins) k = FieldTable::kAlphaBins - 1;  // u just below 360 rounding up
  const double w = u - k;
  const FieldCoefficients& a = ring_[k];
  const FieldCoefficients& b = ring_[k + 1];
  return {a.b1 + w * (b.b1 - a.b1), a.b2 + w * (b.b2 - a.b2), a.b3 + w * (b.b3 - a.b3)};
}

double OrientedField::speed_and_direction(double dx, double dy, double* ux, double* uy) const {
  // (ii) distance and direction from s; the speed is zero at s itself.
  const double r2 = dx * dx + dy * dy;
  if (r2 == 0.0) {
    *ux = *uy = 0.0;
    return 0.0;
  }
  const double r = std::sqrt(r2);
  *ux = dx / r;
  *uy = dy / r;
  // (iii) eq. (3) with the profile of this direction.
  const FieldCoefficients c = coefficients(std::atan2(dy, dx) - orientation_.pan_rad);
  return c.speed(r);
}

double OrientedField::speed(const Eigen::Vector2d& p_W) const {
  double ux, uy;
  return speed_and_direction(p_W.x() - s_W_.x(), p_W.y() - s_W_.y(), &ux, &uy);
}

Eigen::Vector2d OrientedField::velocity(const Eigen::Vector2d& p_W) const {
  double ux, uy;
  const double v = speed_and_direction(p_W.x() - s_W_.x(), p_W.y() - s_W_.y(), &ux, &uy);
  return {v * ux, v * uy};
}

void OrientedField::speeds(const Eigen::Ref<const Eigen::Matrix2Xd>& p_W,
                           Eigen::Ref<Eigen::VectorXd> speed_out) const {
  AIRTWIN_DEMAND(speed_out.size() == p_W.cols());
  double ux, uy;
  for (Eigen::Index j = 0; j < p_W.cols(); ++j) {
    speed_out[j] = speed_and_direction(p_W(0, j) - s_W_.x(), p_W(1, j) - s_W_.y(), &ux, &uy);
  }
}

void OrientedField::velocities(const Eigen::Ref<const Eigen::Matrix2Xd>& p_W,
                               Eigen::Ref<Eigen::Matrix2Xd> v_out) const {
  AIRTWIN_DEMAND(v_out.cols() == p_W.cols());
  double ux, uy;
  for (Eigen::Index j = 0; j < p_W.cols(); ++j) {
    const double v = speed_and_direction(p_W(0, j) - s_W_.x(), p_W(1, j) - s_W_.y(), &ux, &uy);
    v_out(0, j) = v * ux;
    v_out(1, j) = v * uy;
  }
}

}  // namespace airtwin
