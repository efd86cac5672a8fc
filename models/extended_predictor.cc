#include "models/extended_predictor.h"

#include <algorithm>
#include <cmath>

#include "common/errors.h"

namespace airtwin {
namespace {

constexpr double kGravity = 9.81;  // m/s^2
// sqrt(2e): makes strength the peak of (r / l) exp(-(r / l)^2) scaled by it.
const double kPushNorm = std::sqrt(2.0 * std::exp(1.0));

}  // namespace

ExtendedPredictor::ExtendedPredictor(const AirFieldModel& field, double step_s)
    : field_(field), step_(step_s) {
  if (!(std::isfinite(step_s) && step_s > 0.0 && step_s <= 0.05)) {
    throw InputError("extended predictor: step must be in (0, 0.05] s");
  }
  // Just inside the fold of eq. (2), where OrientedField stops accepting tilts.
  max_tilt_rad_ = fold_tilt_rad(field.geometry()) - 1e-6;
}

NozzleOrientation ExtendedPredictor::field_orientation(const ModelExtensions& ext,
                                                       const NozzleTimeline& timeline,
                                                       double t_s) const {
  NozzleOrientation o = timeline.effective(t_s, ext.extra_delay_s);
  o.pan_rad += ext.pan_offset_rad;
  o.tilt_rad = std::clamp(o.tilt_rad + ext.tilt_offset_rad, 0.0, max_tilt_rad_);
  return o;
}

void ExtendedPredictor::predict(const ObjectDynamics& xi, const ModelExtensions& ext,
                                const NozzleTimeline& timeline, const WindowStart& start,
                                std::span<const double> times_s,
                                std::vector<Eigen::Vector2d>* positions) const {
  AIRTWIN_DEMAND(positions != nullptr);
  ext.validate();
  if (!(std::isfinite(start.t_s) && start.p_W.allFinite() && start.v_W.allFinite())) {
    throw InputError("extended predictor: the start state is not finite");
  }
  for (size_t i = 0; i < times_s.size(); ++i) {
    if (!(std::isfinite(times_s[i]) && times_s[i] >= start.t_s &&
          (i == 0 || times_s[i] >= times_s[i - 1]))) {
      throw InputError("extended predictor: sample times must be finite, ordered and not before "
                       "the window's start");
    }
  }
  positions->assign(times_s.size(), start.p_W);
  if (times_s.empty()) return;

  const double kinetic = -xi.xi3;  // |xi3|: kinetic friction deceleration (m/s^2)
  const double static_pull = ext.static_friction_ratio * kinetic;
  const double cos_d = std::cos(ext.deflection_rad), sin_d = std::sin(ext.deflection_rad);
  const Eigen::Vector2d slope =
      kGravity * std::sin(ext.slope_rad) *
      Eigen::Vector2d(std::cos(ext.slope_direction_rad), std::sin(ext.slope_direction_rad));
  const double push_scale = ext.push_strength_mps2 * kPushNorm * ext.field_scale * ext.field_scale;

  NozzleOrientation cached = field_orientation(ext, timeline, start.t_s);
  OrientedField field = field_.at(cached);

  // The acceleration without friction at (p, v) in `field`.
  auto pull = [&](const Eigen::Vector2d& p, const Eigen::Vector2d& v) {
    const Eigen::Vector2d u0 = field.velocity(p);
    const Eigen::Vector2d u =
        ext.field_scale * Eigen::Vector2d(cos_d * u0.x() - sin_d * u0.y(),
                                          sin_d * u0.x() + cos_d * u0.y());
    Eigen::Vector2d a = xi.xi1 * v + xi.xi2 * u + slope;
    if (ext.quadratic_drag_per_m != 0.0) {
      const Eigen::Vector2d rel = u - v;
      a += ext.quadratic_drag_per_m * rel.norm() * rel;
    }
    if (push_scale != 0.0) {
      const Eigen::Vector2d d = p - field.stagnation_point();
      const double r = d.norm();
      if (r > 0.0) {
        const double x = r / ext.push_length_m;
        a += (push_scale * x * std::exp(-x * x) / r) * d;
      }
    }
    return a;
  };

  Eigen::Vector2d p = start.p_W, v = start.v_W;
  bool moving = v.squaredNorm() > 0.0;
  double t = start.t_s;
  const double h = step_;
  size_t next = 0;
  while (next < times_s.size() && times_s[next] <= t) (*positions)[next++] = p;
  while (next < times_s.size()) {
    // The field follows the nozzle: rebuild it when the orientation it follows has changed.
    const NozzleOrientation o = field_orientation(ext, timeline, t);
    if (o.pan_rad != cached.pan_rad || o.tilt_rad != cached.tilt_rad) {
      cached = o;
      field = field_.at(o);
    }
    const Eigen::Vector2d p_old = p;
    if (moving) {
      Eigen::Vector2d v_new = v + h * pull(p, v);
      const double speed = v_new.norm();
      const double friction = h * kinetic;
      if (speed <= friction) {
        v.setZero();  // friction would reverse it: the object stops
        moving = false;
      } else {
        v = v_new * (1.0 - friction / speed);
        p += h * v;
      }
    } else {
      const Eigen::Vector2d a0 = pull(p, Eigen::Vector2d::Zero());
      const double a0_norm = a0.norm();
      if (a0_norm > static_pull) {
        v = h * (a0_norm - kinetic) / a0_norm * a0;
        p += h * v;
        moving = true;
      }
    }
    const double t_new = t + h;
    while (next < times_s.size() && times_s[next] <= t_new) {
      const double f = (times_s[next] - t) / h;
      (*positions)[next++] = p_old + f * (p - p_old);
    }
    t = t_new;
  }
}

}  // namespace airtwin
