#include "models/air_field.h"

#include <algorithm>
#include <cmath>

#include "common/errors.h"
#include "common/units.h"
#include "models/fast_math.h"
#include "models/makima.h"

namespace airtwin {

// Generated at build time from models/data/cfd_fitted_field_model.json (models/CMakeLists.txt).
extern const double kCfdFittedA1;
extern const double kCfdFittedA2;

namespace {

constexpr double kBinsPerRad = FieldTable::kAlphaBins / (2.0 * kPi);

double coefficient(const FieldCoefficients& c, int k) {
  return k == 0 ? c.b1 : k == 1 ? c.b2 : c.b3;
}

// Direction alpha (rad, any value) as 1-degree bin k in [0, 359] and the weight in [0, 1) of bin
// k + 1 (wrapping at 360) for linear interpolation between their profiles.
double alpha_bin(double alpha_rad, int* k) {
  double u = alpha_rad * kBinsPerRad;
  u -= FieldTable::kAlphaBins * std::floor(u / FieldTable::kAlphaBins);
  *k = static_cast<int>(u);
  if (*k >= FieldTable::kAlphaBins) *k = FieldTable::kAlphaBins - 1;  // u just below 360
  return u - *k;
}

}  // namespace

AirFieldModel::AirFieldModel(NozzleGeometry geometry, FieldTable table)
    : geometry_(geometry), table_(std::move(table)) {
  geometry_.validate();
  fold_tilt_rad_ = fold_tilt_rad(geometry_);
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

AirFieldModel AirFieldModel::fitted_to_cfd() {
  NozzleGeometry geometry;
  geometry.a1 = kCfdFittedA1;
  geometry.a2 = kCfdFittedA2;
  return AirFieldModel(geometry, FieldTable::cfd_fitted_table());
}

AirFieldModel AirFieldModel::with_constructed_table() {
  return AirFieldModel(NozzleGeometry{}, FieldTable::constructed_table());
}

OrientedRays AirFieldModel::rays_at(const NozzleOrientation& o) const {
  if (!(std::isfinite(o.pan_rad) && std::isfinite(o.tilt_rad) && o.tilt_rad >= 0 &&
        o.tilt_rad < kPi / 2)) {
    throw InputError("nozzle orientation: pan must be finite and tilt in [0, 90) deg, got pan " +
                     std::to_string(rad_to_deg(o.pan_rad)) + " deg, tilt " +
                     std::to_string(rad_to_deg(o.tilt_rad)) + " deg");
  }
  if (o.tilt_rad >= fold_tilt_rad_) {
    throw InputError("nozzle orientation: tilt " + std::to_string(rad_to_deg(o.tilt_rad)) +
                     " deg is at or beyond the fold of eq. (2) at " +
                     std::to_string(rad_to_deg(fold_tilt_rad_)) +
                     " deg, where the stagnation-point model is not defined");
  }
  OrientedRays f;
  f.model_ = this;
  f.orientation_ = o;
  // (i) eqs. (1), (2), as projection_point() and stagnation_point() compute them (same bits),
  // sharing the projection radius and the pan's direction.
  const double rho_c = geometry_.height_m * std::tan(o.tilt_rad);
  const Eigen::Vector2d direction(std::cos(o.pan_rad), std::sin(o.pan_rad));
  f.c_W_ = rho_c * direction;
  f.s_W_ = stagnation_radius(geometry_, rho_c) * direction;
  f.cos_pan_ = direction.x();
  f.sin_pan_ = direction.y();
  // Makima in tilt, clamped to the fitted range: one set of Hermite weights serves all profiles.
  const std::vector<double>& tilts = table_.tilts_rad();
  double t;
  locate_interval(tilts, o.tilt_rad, &f.tilt_interval_, &t);
  f.coefficient_tilt_rad_ = std::clamp(o.tilt_rad, tilts.front(), tilts.back());
  const size_t i = f.tilt_interval_;
  const HermiteWeights w = hermite_weights(t, tilts[i + 1] - tilts[i]);
  f.tilt_weights_ = {w.h00, w.h10, w.h01, w.h11};
  return f;
}

FieldCoefficients AirFieldModel::profile(const OrientedRays& rays, int a) const {
  const size_t i = rays.tilt_interval_;
  const auto& w = rays.tilt_weights_;
  const FieldCoefficients& y0 = table_.at(i, a);
  const FieldCoefficients& y1 = table_.at(i + 1, a);
  const auto& d0 = slopes_by_tilt_[i][a];
  const auto& d1 = slopes_by_tilt_[i + 1][a];
  return {w[0] * y0.b1 + w[1] * d0[0] + w[2] * y1.b1 + w[3] * d1[0],
          w[0] * y0.b2 + w[1] * d0[1] + w[2] * y1.b2 + w[3] * d1[1],
          w[0] * y0.b3 + w[1] * d0[2] + w[2] * y1.b3 + w[3] * d1[2]};
}

OrientedField AirFieldModel::at(const NozzleOrientation& o) const {
  const OrientedRays rays = rays_at(o);
  OrientedField f;
  f.orientation_ = o;
  f.cos_pan_ = std::cos(o.pan_rad);
  f.sin_pan_ = std::sin(o.pan_rad);
  f.c_W_ = rays.projection_point();
  f.s_W_ = rays.stagnation_point();
  f.coefficient_tilt_rad_ = rays.coefficient_tilt_rad();
  for (int a = 0; a < FieldTable::kAlphaBins; ++a) f.ring_[a] = profile(rays, a);
  f.ring_[FieldTable::kAlphaBins] = f.ring_[0];
  return f;
}

OrientedField OrientedRays::field() const { return model_->at(orientation_); }

FieldCoefficients OrientedRays::coefficients(double alpha_rad) const {
  int k;
  const double w = alpha_bin(alpha_rad, &k);
  const FieldCoefficients a = model_->profile(*this, k);
  const FieldCoefficients b = model_->profile(*this, k + 1 < FieldTable::kAlphaBins ? k + 1 : 0);
  return {a.b1 + w * (b.b1 - a.b1), a.b2 + w * (b.b2 - a.b2), a.b3 + w * (b.b3 - a.b3)};
}

namespace {

// OrientedField::evaluate_block's steps for one point; `profile(k)` gives the profile of 1-degree
// bin k in [0, 360] (360 is bin 0 again).
template <typename Profile>
Eigen::Vector2d point_velocity(const Eigen::Vector2d& p_W, const Eigen::Vector2d& s_W,
                               double cos_pan, double sin_pan, const Profile& profile) {
  const double dx = p_W.x() - s_W.x();
  const double dy = p_W.y() - s_W.y();
  const double r = std::sqrt(dx * dx + dy * dy);
  if (!(r > 0.0)) return Eigen::Vector2d::Zero();
  const double along = cos_pan * dx + sin_pan * dy;
  const double across = cos_pan * dy - sin_pan * dx;
  const double u = fast_atan2(across, along) * kBinsPerRad;  // (-180, 180]
  const double bin = u < 0.0 ? u + FieldTable::kAlphaBins : u;
  int k = static_cast<int>(bin);
  k = k < FieldTable::kAlphaBins ? k : FieldTable::kAlphaBins - 1;
  const double w = bin - k;
  const FieldCoefficients a = profile(k);
  const FieldCoefficients b = profile(k + 1);
  const double b1 = a.b1 + w * (b.b1 - a.b1);
  const double b2r = (a.b2 + w * (b.b2 - a.b2)) * r;
  const double b3r = (a.b3 + w * (b.b3 - a.b3)) * r;
  const double speed = b1 * (fast_exp(b2r) - fast_exp(b3r));
  const double inv = 1.0 / r;
  return {speed * (dx * inv), speed * (dy * inv)};
}

}  // namespace

Eigen::Vector2d OrientedRays::velocity(const Eigen::Vector2d& p_W) const {
  return point_velocity(p_W, s_W_, cos_pan_, sin_pan_, [this](int k) {
    return model_->profile(*this, k < FieldTable::kAlphaBins ? k : 0);
  });
}

FieldCoefficients OrientedField::coefficients(double alpha_rad) const {
  int k;
  const double w = alpha_bin(alpha_rad, &k);
  const FieldCoefficients& a = ring_[k];
  const FieldCoefficients& b = ring_[k + 1];
  return {a.b1 + w * (b.b1 - a.b1), a.b2 + w * (b.b2 - a.b2), a.b3 + w * (b.b3 - a.b3)};
}

// Compiled twice: for AVX2+FMA CPUs (x86-64-v3) and for baseline x86-64, picked at load time.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(AIRTWIN_NO_TARGET_CLONES)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void OrientedField::evaluate_block(const double* x, const double* y, int n, double* speed,
                                  double* ux, double* uy) const {
  AIRTWIN_DEMAND(n >= 0 && n <= kBlock);
  // Plain loops over a block: each vectorises (models/ builds with -fno-trapping-math).
  double dx[kBlock], dy[kBlock], r[kBlock], bin[kBlock], b1[kBlock], b2r[kBlock], b3r[kBlock];
  // (ii) distance from s and direction alpha in the jet frame, as a fractional 1-degree bin.
  for (int i = 0; i < n; ++i) {
    dx[i] = x[i] - s_W_.x();
    dy[i] = y[i] - s_W_.y();
    r[i] = std::sqrt(dx[i] * dx[i] + dy[i] * dy[i]);
    const double along = cos_pan_ * dx[i] + sin_pan_ * dy[i];
    const double across = cos_pan_ * dy[i] - sin_pan_ * dx[i];
    const double u = fast_atan2(across, along) * kBinsPerRad;  // (-180, 180]
    bin[i] = u < 0.0 ? u + FieldTable::kAlphaBins : u;
  }
  // Linear interpolation between the neighbouring profiles (ring_[360] repeats ring_[0]).
  for (int i = 0; i < n; ++i) {
    int k = static_cast<int>(bin[i]);
    k = k < FieldTable::kAlphaBins ? k : FieldTable::kAlphaBins - 1;
    const double w = bin[i] - k;
    const FieldCoefficients& a = ring_[k];
    const FieldCoefficients& b = ring_[k + 1];
    b1[i] = a.b1 + w * (b.b1 - a.b1);
    b2r[i] = (a.b2 + w * (b.b2 - a.b2)) * r[i];
    b3r[i] = (a.b3 + w * (b.b3 - a.b3)) * r[i];
  }
  // (iii) eq. (3); exactly zero at s, where both exponentials are 1.
  for (int i = 0; i < n; ++i) speed[i] = b1[i] * (fast_exp(b2r[i]) - fast_exp(b3r[i]));
  if (ux != nullptr) {
    for (int i = 0; i < n; ++i) {
      const double inv = r[i] > 0.0 ? 1.0 / r[i] : 0.0;
      ux[i] = dx[i] * inv;
      uy[i] = dy[i] * inv;
    }
  }
}

void OrientedField::evaluate(const double* xy, Eigen::Index n, double* speed, double* v_xy) const {
  double x[kBlock], y[kBlock], ux[kBlock], uy[kBlock];
  for (Eigen::Index start = 0; start < n; start += kBlock) {
    const int m = static_cast<int>(std::min<Eigen::Index>(kBlock, n - start));
    for (int i = 0; i < m; ++i) {
      x[i] = xy[2 * (start + i)];
      y[i] = xy[2 * (start + i) + 1];
    }
    evaluate_block(x, y, m, speed + start, v_xy ? ux : nullptr, uy);
    if (v_xy != nullptr) {
      for (int i = 0; i < m; ++i) {
        v_xy[2 * (start + i)] = speed[start + i] * ux[i];
        v_xy[2 * (start + i) + 1] = speed[start + i] * uy[i];
      }
    }
  }
}

double OrientedField::speed(const Eigen::Vector2d& p_W) const {
  double v;
  evaluate_block(&p_W.x(), &p_W.y(), 1, &v, nullptr, nullptr);
  return v;
}

Eigen::Vector2d OrientedField::velocity(const Eigen::Vector2d& p_W) const {
  // One point: the scalar steps, not the block kernel (its setup costs more than the point).
  return point_velocity(p_W, s_W_, cos_pan_, sin_pan_,
                        [this](int k) -> const FieldCoefficients& { return ring_[k]; });
}

void OrientedField::speeds(const Eigen::Ref<const Eigen::Matrix2Xd>& p_W,
                           Eigen::Ref<Eigen::VectorXd> speed_out) const {
  AIRTWIN_DEMAND(speed_out.size() == p_W.cols());
  AIRTWIN_DEMAND(p_W.outerStride() == 2 && speed_out.innerStride() == 1);
  evaluate(p_W.data(), p_W.cols(), speed_out.data(), nullptr);
}

void OrientedField::velocities(const Eigen::Ref<const Eigen::Matrix2Xd>& p_W,
                               Eigen::Ref<Eigen::Matrix2Xd> v_out) const {
  AIRTWIN_DEMAND(v_out.cols() == p_W.cols());
  AIRTWIN_DEMAND(p_W.outerStride() == 2 && v_out.outerStride() == 2);
  thread_local Eigen::VectorXd speed_scratch;
  speed_scratch.resize(p_W.cols());
  evaluate(p_W.data(), p_W.cols(), speed_scratch.data(), v_out.data());
}

}  // namespace airtwin
