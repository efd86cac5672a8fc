#include "models/extended_predictor.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "common/errors.h"

namespace airtwin {
namespace {

constexpr double kGravity = 9.81;  // m/s^2
// sqrt(2e): makes strength the peak of (r / l) exp(-(r / l)^2) scaled by it.
const double kPushNorm = std::sqrt(2.0 * std::exp(1.0));
// Steps under one orientation before the full field (360 profiles, ~1 us) pays for itself
// against reading two profiles per step along rays.
constexpr int kSteadySteps = 16;

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

namespace {

// The catalogue's forces without friction, for one set of extensions and coefficients.
struct Pull {
  Pull(const ObjectDynamics& xi, const ModelExtensions& ext, const ObjectExtensions& object)
      : xi(xi),
        ext(ext),
        object(object),
        cos_d(std::cos(ext.deflection_rad)),
        sin_d(std::sin(ext.deflection_rad)),
        slope(
            kGravity * std::sin(ext.slope_rad) *
            Eigen::Vector2d(std::cos(ext.slope_direction_rad), std::sin(ext.slope_direction_rad))),
        push_scale(ext.push_strength_mps2 * kPushNorm * ext.field_scale * ext.field_scale) {
    // linearised_drag: xi1 v + xi2 u = c (k u - v) = c w, the tangent at |w| = w0 of the
    // quadratic (c / 2 w0) |w| w minus its intercept c w0 / 2 = share |xi3| along w.
    const double c = -xi.xi1;
    if (object.drag_intercept_share > 0.0 && c > 0.0 && xi.xi3 < 0.0) {
      intercept = object.drag_intercept_share * -xi.xi3;
      tangent_speed = 2.0 * intercept / c;
      curvature = 0.5 * c / tangent_speed;
      air_gain = xi.xi2 / c;
    }
  }

  // The acceleration without friction at (p, v) in `field` (an OrientedField or OrientedRays),
  // and the fraction of friction the air's lift leaves there.
  template <typename Field>
  Eigen::Vector2d operator()(const Field& field, const Eigen::Vector2d& p, const Eigen::Vector2d& v,
                             double* friction_left) const {
    const Eigen::Vector2d u0 = field.velocity(p);
    const Eigen::Vector2d u = ext.field_scale * Eigen::Vector2d(cos_d * u0.x() - sin_d * u0.y(),
                                                                sin_d * u0.x() + cos_d * u0.y());
    *friction_left = object.lift_s2_per_m2 > 0.0
                         ? std::max(0.0, 1.0 - object.lift_s2_per_m2 * (u - v).squaredNorm())
                         : 1.0;
    Eigen::Vector2d a = slope;
    if (tangent_speed > 0.0) {
      const Eigen::Vector2d w = air_gain * u - v;
      const double n = w.norm();
      if (n >= tangent_speed) {
        a += (-xi.xi1 - intercept / n) * w;
      } else {
        a += curvature * n * w;
      }
    } else {
      a += xi.xi1 * v + xi.xi2 * u;
    }
    if (object.quadratic_drag_per_m != 0.0) {
      const Eigen::Vector2d rel = u - v;
      a += object.quadratic_drag_per_m * rel.norm() * rel;
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
  }

  const ObjectDynamics& xi;
  const ModelExtensions& ext;
  const ObjectExtensions& object;
  double cos_d, sin_d;
  Eigen::Vector2d slope;
  double push_scale;
  // linearised_drag (tangent_speed 0: off): w0 (m/s), the intercept c w0 / 2 (m/s^2) that eq.
  // (8)'s friction holds, the quadratic's c / 2 w0 (1/m) and k = xi2 / c.
  double tangent_speed = 0.0, intercept = 0.0, curvature = 0.0, air_gain = 0.0;
};

// One object's state and its semi-implicit Euler step with Coulomb friction.
struct Mover {
  Mover(const Pull& pull, const Eigen::Vector2d& p0, const Eigen::Vector2d& v0)
      : pull(pull),
        kinetic(std::max(0.0, -pull.xi.xi3 - pull.intercept)),
        static_pull(pull.ext.static_friction_ratio * kinetic),
        p(p0),
        v(v0),
        moving(v0.squaredNorm() > 0.0) {}

  template <typename Field>
  void step(const Field& field, double h) {
    double left = 1.0;  // the fraction of friction the lift leaves
    if (moving) {
      const Eigen::Vector2d v_new = v + h * pull(field, p, v, &left);
      const double speed = v_new.norm();
      const double friction = h * kinetic * left;
      if (speed <= friction) {
        v.setZero();  // friction would reverse it: the object stops
        moving = false;
      } else {
        v = v_new * (1.0 - friction / speed);
        p += h * v;
      }
    } else if (!held) {
      const Eigen::Vector2d a0 = pull(field, p, Eigen::Vector2d::Zero(), &left);
      const double a0_norm = a0.norm();
      if (a0_norm > static_pull * left) {
        v = h * (a0_norm - kinetic * left) / a0_norm * a0;
        p += h * v;
        moving = true;
      } else {
        held = true;  // the same field at the same point: held until the field changes
      }
    }
  }
  // The field changed: an object held at rest must be checked again.
  void field_changed() { held = false; }

  const Pull& pull;
  double kinetic;      // |xi3|: kinetic friction deceleration (m/s^2)
  double static_pull;  // the pull that starts an object at rest (m/s^2)
  Eigen::Vector2d p, v;
  bool moving;
  bool held = false;  // at rest, and the pull at p in the current field did not start it
};

// The orientations the air followed around a window, for the transport lag: runs of one
// orientation on the predictor's time grid, from kMaxTransportLagS before the window's start to
// its end. A point p feels at t the newest orientation o(t') whose air has spread to it from its
// stagnation point s(t'): t - t' >= min(pace |p - s(t')|, kMaxTransportLagS). Within a run s is
// fixed, so the newest run with an admissible t' is the answer.
class FrontHistory {
 public:
  FrontHistory(const ExtendedPredictor& predictor, const ModelExtensions& ext,
               const NozzleTimeline& timeline, double t0_s, double t_end_s, double h)
      : pace_(ext.transport_pace_s_per_m), t0_(t0_s), h_(h) {
    first_ = -static_cast<long>(std::ceil(kMaxTransportLagS / h)) - 1;
    const long last = static_cast<long>(std::ceil((t_end_s - t0_s) / h)) + 1;
    run_of_.reserve(static_cast<size_t>(last - first_ + 1));
    for (long j = first_; j <= last; ++j) {
      const double t = t0_s + static_cast<double>(j) * h;
      const NozzleOrientation o = predictor.field_orientation(ext, timeline, t);
      if (runs_.empty() || o.pan_rad != runs_.back().rays.orientation().pan_rad ||
          o.tilt_rad != runs_.back().rays.orientation().tilt_rad) {
        runs_.push_back({t, predictor.field().rays_at(o)});
      }
      run_of_.push_back(runs_.size() - 1);
    }
    runs_.front().t_from_s = -INFINITY;  // the air of before the history has reached everywhere
  }

  // The orientation a point at p feels at time t.
  const NozzleOrientation& felt(double t, const Eigen::Vector2d& p) const {
    const long j = static_cast<long>(std::floor((t - t0_) / h_ + 1e-6)) - first_;
    size_t i = run_of_[static_cast<size_t>(std::clamp<long>(j, 0, std::ssize(run_of_) - 1))];
    for (;; --i) {
      const Run& r = runs_[i];
      if (i == 0 || t - lag_s(p, r) >= r.t_from_s - 1e-9) return r.rays.orientation();
    }
  }
  // The time from which a point at p feels the last orientation.
  double settled_at(const Eigen::Vector2d& p) const {
    return runs_.back().t_from_s + lag_s(p, runs_.back());
  }

 private:
  struct Run {
    double t_from_s;    // when the air began to follow this orientation at s
    OrientedRays rays;  // the orientation, its s
  };
  double lag_s(const Eigen::Vector2d& p, const Run& r) const {
    return std::min(pace_ * (p - r.rays.stagnation_point()).norm(), kMaxTransportLagS);
  }
  double pace_, t0_, h_;
  long first_ = 0;  // grid index of the history's first sample (before t0)
  std::vector<Run> runs_;
  std::vector<size_t> run_of_;  // each sample's run
};

// What one object feels while the field changes: read along rays (two profiles per step) until
// its orientation has held for kSteadySteps, then as the full field.
struct FeltField {
  FeltField(const AirFieldModel& model, const NozzleOrientation& o)
      : model(model), orientation(o), rays(model.rays_at(o)) {}
  FeltField(const AirFieldModel& model, const OrientedRays& r)
      : model(model), orientation(r.orientation()), rays(r) {}
  // Moves on to orientation o; true when the field changed (an object held at rest must then be
  // checked again).
  bool update(const NozzleOrientation& o) {
    if (o.pan_rad != orientation.pan_rad || o.tilt_rad != orientation.tilt_rad) {
      return moved_to(model.rays_at(o));
    }
    return held_still();
  }
  // The same with the orientation's rays already worked out (an OrientationTrack's).
  bool update(const OrientedRays& r) {
    const NozzleOrientation& o = r.orientation();
    if (o.pan_rad != orientation.pan_rad || o.tilt_rad != orientation.tilt_rad) return moved_to(r);
    return held_still();
  }
  bool moved_to(const OrientedRays& r) {
    orientation = r.orientation();
    rays = r;
    have_field = false;
    steady = 0;
    return true;
  }
  bool held_still() {
    if (!have_field && ++steady >= kSteadySteps) {
      field = rays.field();
      have_field = true;
      return true;
    }
    return false;
  }
  void step(Mover& object, double h) const {
    if (have_field) {
      object.step(field, h);
    } else {
      object.step(rays, h);
    }
  }

  const AirFieldModel& model;
  NozzleOrientation orientation;
  OrientedRays rays;
  OrientedField field;
  bool have_field = false;
  int steady = 0;
};

// The predictor moves objects of one type under ModelExtensions::object; a type's own per_type
// effects are resolved by the caller (ModelExtensions::for_type), never silently dropped.
void require_one_type(const ModelExtensions& ext) {
  if (!ext.object_by_type.empty()) {
    throw InputError("extended predictor: the extensions hold " +
                     std::string(ext.object_by_type.begin()->first) +
                     "'s own effects; predict with the extensions for_type() of the object");
  }
}

}  // namespace

bool OrientationTrack::serves(const ModelExtensions& ext, const NozzleTimeline& timeline,
                              double t0_s, double step_s) const {
  return timeline_ == &timeline && t0_s_ == t0_s && step_s_ == step_s &&
         ext.transport_pace_s_per_m == 0.0 && extra_delay_s_ == ext.extra_delay_s &&
         pan_offset_rad_ == ext.pan_offset_rad && tilt_offset_rad_ == ext.tilt_offset_rad;
}

size_t OrientationTrack::bytes() const {
  return sizeof(OrientationTrack) + run_of_step_.size() * sizeof(unsigned) +
         runs_.size() * sizeof(OrientedRays);
}

OrientationTrack ExtendedPredictor::track(const ModelExtensions& ext,
                                          const NozzleTimeline& timeline, double t0_s,
                                          double t_end_s) const {
  if (ext.transport_pace_s_per_m > 0.0) {
    throw InputError(
        "extended predictor: with the transport lag each point feels its own "
        "orientation, which no track holds");
  }
  if (!(std::isfinite(t0_s) && std::isfinite(t_end_s))) {
    throw InputError("extended predictor: a track's times must be finite");
  }
  OrientationTrack k;
  k.field_ = &field_;
  k.timeline_ = &timeline;
  k.t0_s_ = t0_s;
  k.step_s_ = step_;
  k.extra_delay_s_ = ext.extra_delay_s;
  k.pan_offset_rad_ = ext.pan_offset_rad;
  k.tilt_offset_rad_ = ext.tilt_offset_rad;
  // The steps predict() takes: t summed step by step, as there, while a sample is still ahead.
  for (double t = t0_s;; t += step_) {
    const NozzleOrientation o = field_orientation(ext, timeline, t);
    if (k.runs_.empty() || o.pan_rad != k.runs_.back().orientation().pan_rad ||
        o.tilt_rad != k.runs_.back().orientation().tilt_rad) {
      k.runs_.push_back(field_.rays_at(o));
    }
    k.run_of_step_.push_back(static_cast<unsigned>(k.runs_.size() - 1));
    if (!(t < t_end_s)) break;
  }
  return k;
}

void ExtendedPredictor::predict(const ObjectDynamics& xi, const ModelExtensions& ext,
                                const NozzleTimeline& timeline, const WindowStart& start,
                                std::span<const double> times_s,
                                std::vector<Eigen::Vector2d>* positions,
                                const OrientationTrack* track) const {
  AIRTWIN_DEMAND(positions != nullptr);
  ext.validate();
  require_one_type(ext);
  if (!(std::isfinite(start.t_s) && start.p_W.allFinite() && start.v_W.allFinite())) {
    throw InputError("extended predictor: the start state is not finite");
  }
  for (size_t i = 0; i < times_s.size(); ++i) {
    if (!(std::isfinite(times_s[i]) && times_s[i] >= start.t_s &&
          (i == 0 || times_s[i] >= times_s[i - 1]))) {
      throw InputError(
          "extended predictor: sample times must be finite, ordered and not before "
          "the window's start");
    }
  }
  positions->assign(times_s.size(), start.p_W);
  if (times_s.empty()) return;

  // With the transport lag, the orientation the object feels comes from the front's history.
  const double h = step_;
  std::optional<FrontHistory> front;
  if (ext.transport_pace_s_per_m > 0.0) {
    front.emplace(*this, ext, timeline, start.t_s, times_s.back(), h);
  }
  auto felt = [&](double t, const Eigen::Vector2d& p) {
    return front ? front->felt(t, p) : field_orientation(ext, timeline, t);
  };
  // The orientations from the caller's track where it serves (the same ones, worked out once).
  if (track != nullptr &&
      (front || track->field_ != &field_ || !track->serves(ext, timeline, start.t_s, h))) {
    track = nullptr;
  }
  size_t step = 0;
  // While the nozzle moves the orientation changes every step: the field is then read along rays
  // (two profiles per step); once it has held still for kSteadySteps the full field is built.
  FeltField air = track != nullptr ? FeltField(field_, track->runs_[track->run_of_step_[0]])
                                   : FeltField(field_, felt(start.t_s, start.p_W));
  const Pull pull(xi, ext, ext.object);
  Mover object(pull, start.p_W, start.v_W);
  double t = start.t_s;
  size_t next = 0;
  while (next < times_s.size() && times_s[next] <= t) (*positions)[next++] = object.p;
  // From here on the field no longer changes: an object held at rest then stays where it is.
  const double settled_s =
      timeline.settled_from_s() + timeline.parameters().transit_delay_s + ext.extra_delay_s;
  while (next < times_s.size()) {
    if (object.held && air.have_field &&
        t > (front ? std::max(settled_s, front->settled_at(object.p)) : settled_s)) {
      while (next < times_s.size()) (*positions)[next++] = object.p;
      break;
    }
    // The field follows the nozzle: a new one when the orientation it follows has changed.
    const bool changed = track != nullptr && step < track->run_of_step_.size()
                             ? air.update(track->runs_[track->run_of_step_[step]])
                             : air.update(felt(t, object.p));
    if (changed) object.field_changed();
    ++step;
    const Eigen::Vector2d p_old = object.p;
    air.step(object, h);
    const double t_new = t + h;
    while (next < times_s.size() && times_s[next] <= t_new) {
      const double f = (times_s[next] - t) / h;
      (*positions)[next++] = p_old + f * (object.p - p_old);
    }
    t = t_new;
  }
}

void ExtendedPredictor::predict_ends(std::span<const ObjectDynamics> xi, const ModelExtensions& ext,
                                     std::span<const ObjectExtensions> objects_ext,
                                     const NozzleTimeline& timeline,
                                     std::span<const WindowStart> starts, double t_end_s,
                                     std::span<Eigen::Vector2d> ends) const {
  ext.validate();
  if (objects_ext.empty()) require_one_type(ext);
  if (xi.size() != starts.size() || ends.size() != starts.size() ||
      !(objects_ext.empty() || objects_ext.size() == starts.size())) {
    throw InputError(
        "extended predictor: coefficients, object extensions, starts and ends differ in number");
  }
  for (const ObjectExtensions& o : objects_ext) {
    ModelExtensions check;
    check.object = o;
    check.validate();
  }
  if (starts.empty()) return;
  const double t0 = starts[0].t_s;
  for (const WindowStart& s : starts) {
    if (!(std::isfinite(s.t_s) && s.p_W.allFinite() && s.v_W.allFinite())) {
      throw InputError("extended predictor: a start state is not finite");
    }
    if (s.t_s != t0) throw InputError("extended predictor: the objects start at different times");
  }
  if (!(std::isfinite(t_end_s) && t_end_s >= t0)) {
    throw InputError("extended predictor: the end time must be finite and not before the start");
  }
  // Every object's pull and state, side by side (a decision has tens of objects at most).
  std::vector<Pull> pulls;
  pulls.reserve(starts.size());
  for (size_t j = 0; j < starts.size(); ++j)
    pulls.emplace_back(xi[j], ext, objects_ext.empty() ? ext.object : objects_ext[j]);
  std::vector<Mover> objects;
  objects.reserve(starts.size());
  for (size_t j = 0; j < starts.size(); ++j)
    objects.emplace_back(pulls[j], starts[j].p_W, starts[j].v_W);
  std::vector<Eigen::Vector2d> p_old(starts.size());

  double t = t0;
  const double h = step_;
  if (t_end_s <= t) {
    for (size_t j = 0; j < objects.size(); ++j) ends[j] = objects[j].p;
    return;
  }
  // Without the transport lag every object feels one field per step (rebuilt when the
  // orientation changes); with it each object feels its own orientation, stepped as predict()
  // steps one. The same interpolation inside the last step as predict().
  std::optional<FrontHistory> front;
  std::vector<FeltField> airs;
  NozzleOrientation cached = field_orientation(ext, timeline, t0);
  // Only the rays the objects need, not the orientation's 360 profiles: rebuilt at every step
  // while the servos turn.
  OrientedRays field;
  if (ext.transport_pace_s_per_m > 0.0) {
    front.emplace(*this, ext, timeline, t0, t_end_s, h);
    airs.reserve(objects.size());
    for (size_t j = 0; j < objects.size(); ++j) {
      airs.emplace_back(field_, front->felt(t0, starts[j].p_W));
    }
  } else {
    field = field_.rays_at(cached);
  }
  while (true) {
    if (front) {
      for (size_t j = 0; j < objects.size(); ++j) {
        if (airs[j].update(front->felt(t, objects[j].p))) objects[j].field_changed();
        p_old[j] = objects[j].p;
        airs[j].step(objects[j], h);
      }
    } else {
      const NozzleOrientation o = field_orientation(ext, timeline, t);
      if (o.pan_rad != cached.pan_rad || o.tilt_rad != cached.tilt_rad) {
        cached = o;
        field = field_.rays_at(o);
        for (Mover& m : objects) m.field_changed();
      }
      for (size_t j = 0; j < objects.size(); ++j) {
        p_old[j] = objects[j].p;
        objects[j].step(field, h);
      }
    }
    const double t_new = t + h;
    if (t_end_s <= t_new) {
      const double f = (t_end_s - t) / h;
      for (size_t j = 0; j < objects.size(); ++j) {
        ends[j] = p_old[j] + f * (objects[j].p - p_old[j]);
      }
      return;
    }
    t = t_new;
  }
}

}  // namespace airtwin
