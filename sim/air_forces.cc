#include "sim/air_forces.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <mutex>

#include "common/errors.h"

namespace airtwin {
namespace {

// The registration of the calling thread: which AirForces pushes which model.
struct Registration {
  const mjModel* model = nullptr;
  AirForces* forces = nullptr;
};
thread_local Registration t_registration;

// The one mjcb_passive of the process. Plain C linkage, never throws.
extern "C" void passive_dispatch(const mjModel* m, mjData* d) {
  const Registration& r = t_registration;
  if (r.forces != nullptr && r.model == m) r.forces->apply(m, d);
}

std::once_flag g_install_once;

}  // namespace

AirForceParameters AirForceParameters::none() {
  AirForceParameters p;
  p.turbulence_near = 0.0;
  p.turbulence_far = 0.0;
  p.stagnation_pressure_pa = 0.0;
  return p;
}

void AirForceParameters::validate() const {
  auto check = [](bool ok, const char* field, double v) {
    if (!ok) {
      throw InputError(std::string("air-force parameters: ") + field + " is out of range, got " +
                       std::to_string(v));
    }
  };
  check(std::isfinite(turbulence_near) && turbulence_near >= 0 && turbulence_near <= 1,
        "turbulence_near (expected [0, 1])", turbulence_near);
  check(std::isfinite(turbulence_far) && turbulence_far >= 0 && turbulence_far <= 1,
        "turbulence_far (expected [0, 1])", turbulence_far);
  check(std::isfinite(turbulence_length_m) && turbulence_length_m > 0,
        "turbulence_length_m (expected > 0)", turbulence_length_m);
  check(std::isfinite(turbulence_reference_speed_mps) && turbulence_reference_speed_mps >= 0,
        "turbulence_reference_speed_mps (expected >= 0)", turbulence_reference_speed_mps);
  check(std::isfinite(turbulence_time_s) && turbulence_time_s > 0,
        "turbulence_time_s (expected > 0)", turbulence_time_s);
  check(std::isfinite(stagnation_pressure_pa) && stagnation_pressure_pa >= 0,
        "stagnation_pressure_pa (expected >= 0)", stagnation_pressure_pa);
  check(std::isfinite(pressure_radius_m) && pressure_radius_m > 0,
        "pressure_radius_m (expected > 0)", pressure_radius_m);
}

AirForces::AirForces(const AirForceParameters& params, const SceneParameters& scene,
                     std::vector<SceneObject> objects, uint64_t seed, double timestep_s)
    : params_(params), objects_(std::move(objects)) {
  params_.validate();
  AIRTWIN_DEMAND(std::isfinite(timestep_s) && timestep_s > 0);
  // Exact discretisation of the unit-variance OU process over one step.
  ou_decay_ = std::exp(-timestep_s / params_.turbulence_time_s);
  ou_kick_ = std::sqrt(std::max(0.0, 1.0 - ou_decay_ * ou_decay_));
  // Per-object coefficients and turbulence streams, the OU state drawn from its stationary law.
  for (size_t o = 0; o < objects_.size(); ++o) {
    const SceneObject& obj = objects_[o];
    AIRTWIN_DEMAND(obj.bodies.size() <= kMaxBodiesPerObject &&
                   obj.bodies.size() == obj.area_share.size());
    const ObjectTypeParameters& t = scene.of(obj.type);
    streams_.emplace_back(seed, RandomPurpose::kTurbulence, o);
    PerObject p;
    p.drag_coefficient = obj.mass_kg * t.drag_rate_per_s;
    p.air_gain = t.air_gain;
    p.pressure_volume = t.pressure_volume_m3;
    p.extra_static = (t.static_friction_ratio - 1.0) * t.kinetic_friction * obj.mass_kg;
    p.stiction_speed = t.stiction_speed_mps;
    const double ex = streams_.back().normal();
    const double ey = streams_.back().normal();
    p.eta = Eigen::Vector2d(ex, ey);
    per_object_.push_back(p);
  }
}

void AirForces::set_air(const OrientedField& field, double jet_level) {
  field_ = &field;
  jet_level_ = jet_level;
}

void AirForces::advance_turbulence() {
  for (size_t o = 0; o < per_object_.size(); ++o) {
    const double ex = streams_[o].normal();
    const double ey = streams_[o].normal();
    per_object_[o].eta = ou_decay_ * per_object_[o].eta + ou_kick_ * Eigen::Vector2d(ex, ey);
  }
}

Eigen::Vector2d AirForces::turbulence_state(size_t o) const {
  AIRTWIN_DEMAND(o < per_object_.size());
  return per_object_[o].eta;
}

void AirForces::apply(const mjModel* m, mjData* d) noexcept {
  if (!fault_.empty()) return;
  try {
    apply_unchecked(m, d);
  } catch (const std::exception& e) {
    fault_ = std::string("air-force callback failed: ") + e.what();
  } catch (...) {
    fault_ = "air-force callback failed with an unknown exception";
  }
}

void AirForces::apply_unchecked(const mjModel* m, mjData* d) {
  if (field_ == nullptr || jet_level_ <= 0.0) {
    // No air: only the holding force could act, and it opposes air forces only.
    return;
  }
  const Eigen::Vector2d s_W = field_->stagnation_point();
  const double g = std::abs(m->opt.gravity[2]);
  const double b2 = params_.pressure_radius_m * params_.pressure_radius_m;
  const double push = jet_level_ * jet_level_ * params_.stagnation_pressure_pa;
  const double i_near = params_.turbulence_near, i_far = params_.turbulence_far;
  const double lt2 = params_.turbulence_length_m * params_.turbulence_length_m;

  for (size_t o = 0; o < objects_.size(); ++o) {
    const SceneObject& obj = objects_[o];
    const PerObject& po = per_object_[o];
    const size_t n = obj.bodies.size();

    // The object's centre and velocity (area-weighted), and its turbulent air velocity.
    Eigen::Vector2d centre = Eigen::Vector2d::Zero(), v_obj = Eigen::Vector2d::Zero();
    for (size_t k = 0; k < n; ++k) {
      const int b = obj.bodies[k];
      centre += obj.area_share[k] * Eigen::Vector2d(d->xipos[3 * b], d->xipos[3 * b + 1]);
      v_obj += obj.area_share[k] * body_com_velocity(m, d, b).head<2>();
    }
    const double r_obj2 = (centre - s_W).squaredNorm();
    const double sigma = params_.turbulence_reference_speed_mps *
                         (i_far + (i_near - i_far) * std::exp(-r_obj2 / lt2));
    const Eigen::Vector2d u_turbulent = sigma * po.eta;

    // Drag and pressure push on each body, by its area share.
    Eigen::Vector2d total = Eigen::Vector2d::Zero();
    Eigen::Vector2d body_force[kMaxBodiesPerObject];
    for (size_t k = 0; k < n; ++k) {
      const int b = obj.bodies[k];
      const double w = obj.area_share[k];
      const Eigen::Vector2d p(d->xipos[3 * b], d->xipos[3 * b + 1]);
      const Eigen::Vector2d v = body_com_velocity(m, d, b).head<2>();
      const Eigen::Vector2d u = jet_level_ * (field_->velocity(p) + u_turbulent);
      Eigen::Vector2d f = w * po.drag_coefficient * (po.air_gain * u - v);
      const Eigen::Vector2d from_s = p - s_W;
      const double r2 = from_s.squaredNorm();
      if (push > 0.0 && r2 > 0.0) {
        // -dp/dr along the unit radial direction: 2 r / b^2 p exp(-r^2/b^2) * (from_s / r).
        f += w * po.pressure_volume * push * (2.0 / b2) * std::exp(-r2 / b2) * from_s;
      }
      body_force[k] = f;
      total += f;
    }

    // Static friction beyond kinetic: hold against the push while (nearly) at rest.
    Eigen::Vector2d hold = Eigen::Vector2d::Zero();
    const double total_norm = total.norm();
    if (po.extra_static > 0.0 && total_norm > 0.0) {
      const double fade = std::exp(-v_obj.squaredNorm() / (po.stiction_speed * po.stiction_speed));
      hold = -(std::min(total_norm, po.extra_static * g) * fade / total_norm) * total;
    }

    // Apply at each body's centre of mass.
    for (size_t k = 0; k < n; ++k) {
      const int b = obj.bodies[k];
      const Eigen::Vector2d f = body_force[k] + obj.area_share[k] * hold;
      const mjtNum force[3] = {f.x(), f.y(), 0.0};
      const mjtNum torque[3] = {0.0, 0.0, 0.0};
      mj_applyFT(m, d, force, torque, d->xpos + 3 * b, b, d->qfrc_passive);
    }
  }
}

AirForcesScope::AirForcesScope(const mjModel* model, AirForces* forces)
    : previous_model_(t_registration.model), previous_forces_(t_registration.forces) {
  std::call_once(g_install_once, [] { mjcb_passive = passive_dispatch; });
  // Someone else replacing the process-wide callback would silently switch the air off.
  AIRTWIN_DEMAND(mjcb_passive == passive_dispatch);
  t_registration = Registration{model, forces};
}

AirForcesScope::~AirForcesScope() {
  t_registration = Registration{previous_model_, previous_forces_};
}

}  // namespace airtwin
