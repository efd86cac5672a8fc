#include "sim/air_forces.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <mutex>

#include "common/errors.h"
#include "common/units.h"
#include "models/turbulence_time.h"

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
  check(std::isfinite(lagrangian_time_factor) && lagrangian_time_factor > 0,
        "lagrangian_time_factor (expected > 0)", lagrangian_time_factor);
  check(std::isfinite(field_scale) && field_scale > 0, "field_scale (expected > 0)", field_scale);
  check(std::isfinite(flow_deflection_rad) && std::abs(flow_deflection_rad) <= kPi / 2,
        "flow_deflection_rad (expected [-pi/2, pi/2])", flow_deflection_rad);
  check(std::isfinite(extra_push_mps2) && extra_push_mps2 >= 0, "extra_push_mps2 (expected >= 0)",
        extra_push_mps2);
  check(std::isfinite(extra_push_length_m) && extra_push_length_m > 0,
        "extra_push_length_m (expected > 0)", extra_push_length_m);
}

AirForces::AirForces(const AirForceParameters& params, const SceneParameters& scene,
                     std::vector<SceneObject> objects, uint64_t seed, double timestep_s)
    : params_(params), objects_(std::move(objects)) {
  params_.validate();
  AIRTWIN_DEMAND(std::isfinite(timestep_s) && timestep_s > 0);
  // Exact discretisation of the unit-variance OU process over one step.
  timestep_s_ = timestep_s;
  ou_decay_ = std::exp(-timestep_s / params_.turbulence_time_s);
  ou_kick_ = std::sqrt(std::max(0.0, 1.0 - ou_decay_ * ou_decay_));
  // Per-object coefficients and turbulence streams, the OU state drawn from its stationary law.
  for (size_t o = 0; o < objects_.size(); ++o) {
    const SceneObject& obj = objects_[o];
    AIRTWIN_DEMAND(obj.bodies.size() <= kMaxBodiesPerObject &&
                   obj.bodies.size() == obj.area_share.size());
    const ObjectTypeParameters& t = physics_of(obj, scene);
    if (t.drag_law == DragLaw::kPhysical &&
        !(t.drag_coefficient >= 0.0 && t.frontal_area_m2 > 0.0 && t.drag_length_m > 0.0 &&
          scene.air_density_kgpm3 > 0.0 && scene.air_viscosity_m2ps > 0.0)) {
      throw InputError("object '" + obj.id + "' (" + object_type_name(obj.type) + ")" +
                       ": physical drag needs drag_coefficient >= 0, frontal_area_m2 > 0, "
                       "drag_length_m > 0 and a positive air density and viscosity");
    }
    streams_.emplace_back(seed, RandomPurpose::kTurbulence, o);
    PerObject p;
    p.physical = t.drag_law == DragLaw::kPhysical;
    p.quadratic = 0.5 * scene.air_density_kgpm3 * t.drag_coefficient * t.frontal_area_m2;
    p.viscous = p.physical ? 12.0 * scene.air_density_kgpm3 * t.frontal_area_m2 *
                                 scene.air_viscosity_m2ps / t.drag_length_m
                           : 0.0;
    const double r = 0.5 * t.diameter_m;
    p.lift = p.physical ? 0.5 * scene.air_density_kgpm3 * t.lift_coefficient * kPi * r * r : 0.0;
    p.drag_coefficient = obj.mass_kg * t.drag_rate_per_s;
    p.tangent_speed = 0.0;
    p.intercept_force = 0.0;
    p.unload_share = 0.0;
    p.extra_quadratic = t.extra_quadratic_drag_per_m;
    p.extra_lift = t.extra_lift_s2pm2;
    any_unload_ = any_unload_ || t.drag_intercept_share > 0.0;
    const double share = t.drag_intercept_share;
    if (share > 0.0) {
      // linearised_drag: eq. (8)'s law read as the tangent of a quadratic drag.
      if (p.physical) {
        throw InputError(
            "object parameters: drag_intercept_share (linearised_drag) bends "
            "eq. (8)'s linear drag; object '" +
            obj.id + "' (" + object_type_name(obj.type) +
            ") has the physical drag law, quadratic already");
      }
      const double intercept = share * t.kinetic_friction * std::abs(scene.gravity_W().z());
      if (t.drag_rate_per_s > 0.0 && intercept > 0.0) {
        p.tangent_speed = 2.0 * intercept / t.drag_rate_per_s;
        p.intercept_force = obj.mass_kg * intercept;
        p.unload_share = share;
      }
    }
    p.air_gain = t.air_gain;
    p.pressure_volume = t.pressure_volume_m3;
    p.extra_static = (t.static_friction_ratio - 1.0) * t.kinetic_friction * obj.mass_kg;
    p.kinetic = t.kinetic_friction * obj.mass_kg;
    p.stiction_speed = t.stiction_speed_mps;
    p.sticking = true;
    p.pull = 0.0;
    p.load = 0.0;
    p.speed = 0.0;
    const double ex = streams_.back().normal();
    const double ey = streams_.back().normal();
    p.eta = Eigen::Vector2d(ex, ey);
    p.decay = ou_decay_;
    p.kick = ou_kick_;
    per_object_.push_back(p);
  }
  // The flattened body layout and the scratch columns, sized once.
  size_t n_bodies = 0;
  for (const SceneObject& obj : objects_) {
    first_body_.push_back(n_bodies);
    n_bodies += obj.bodies.size();
  }
  first_body_.push_back(n_bodies);
  const Eigen::Index n = static_cast<Eigen::Index>(n_bodies);
  p_body_W_.setZero(2, n);
  v_body_W_.setZero(2, n);
  u_body_W_.setZero(2, n);
  f_body_W_.setZero(2, n);
  grad_p_body_W_.setZero(2, n);
  air_density_ = scene.air_density_kgpm3;
  z_body_.setZero(n);
  k_body_.setZero(n);
  epsilon_body_.setZero(n);
  lift_body_.setZero(n);
  object_cfd_.assign(objects_.size(), nullptr);
  object_rays_.assign(objects_.size(), nullptr);
  object_departure_.assign(objects_.size(), Eigen::Vector2d::Zero());
  cos_deflection_ = std::cos(params_.flow_deflection_rad);
  sin_deflection_ = std::sin(params_.flow_deflection_rad);
}

void AirForces::set_air(const OrientedField& field, double jet_level) {
  field_ = &field;
  cfd_ = nullptr;
  jet_level_ = jet_level;
}

void AirForces::set_air(const CfdOrientedField& field, double jet_level) {
  cfd_ = &field;
  field_ = nullptr;
  jet_level_ = jet_level;
}

Eigen::Vector2d AirForces::mean_air(const Eigen::Vector2d& p_W, double z_m) const {
  const double scale = jet_level_ * params_.field_scale;
  if (cfd_ != nullptr) return scale * turned(cfd_->at(p_W, z_m).u_W);
  if (field_ != nullptr) return scale * turned(field_->velocity(p_W));
  return Eigen::Vector2d::Zero();
}

void AirForces::set_object_air(size_t o, const CfdOrientedField& field) {
  AIRTWIN_DEMAND(o < objects_.size() && cfd_ != nullptr);
  object_cfd_[o] = &field;
  any_object_air_ = true;
}

void AirForces::set_object_air(size_t o, const OrientedRays& rays) {
  AIRTWIN_DEMAND(o < objects_.size() && field_ != nullptr);
  object_rays_[o] = &rays;
  any_object_air_ = true;
}

void AirForces::set_object_air_departure(size_t o, const Eigen::Vector2d& departure) {
  AIRTWIN_DEMAND(o < objects_.size() && cfd_ != nullptr);
  object_departure_[o] = departure;
  any_object_air_ = true;
}

void AirForces::clear_object_air() {
  if (!any_object_air_) return;
  std::fill(object_cfd_.begin(), object_cfd_.end(), nullptr);
  std::fill(object_rays_.begin(), object_rays_.end(), nullptr);
  std::fill(object_departure_.begin(), object_departure_.end(), Eigen::Vector2d::Zero());
  any_object_air_ = false;
}

Eigen::Vector2d AirForces::object_mean_air(size_t o, const Eigen::Vector2d& p_W, double z_m) const {
  AIRTWIN_DEMAND(o < objects_.size());
  if (field_ != nullptr && object_rays_[o] != nullptr) {
    return jet_level_ * params_.field_scale * turned(object_rays_[o]->velocity(p_W));
  }
  if (cfd_ == nullptr || object_cfd_[o] == nullptr) {
    const Eigen::Vector2d common = mean_air(p_W, z_m);
    if (cfd_ == nullptr) return common;
    return common + jet_level_ * params_.field_scale * turned(object_departure_[o]);
  }
  return jet_level_ * params_.field_scale *
         turned(object_cfd_[o]->at(p_W, z_m).u_W + object_departure_[o]);
}

void AirForces::advance_turbulence() {
  for (size_t o = 0; o < per_object_.size(); ++o) {
    PerObject& po = per_object_[o];
    const bool cfd = cfd_ != nullptr;
    const double decay = cfd ? po.decay : ou_decay_, kick = cfd ? po.kick : ou_kick_;
    const double ex = streams_[o].normal();
    const double ey = streams_[o].normal();
    po.eta = decay * po.eta + kick * Eigen::Vector2d(ex, ey);
  }
}

void AirForces::advance_friction() {
  for (PerObject& po : per_object_) {
    // Stuck objects hold up to mu_s N; sliding ones stop only where kinetic friction wins.
    const double limit = (po.sticking ? po.extra_static + po.kinetic : po.kinetic) * po.load;
    po.sticking = po.speed < po.stiction_speed && po.pull <= limit;
  }
}

bool AirForces::sticking(size_t o) const {
  AIRTWIN_DEMAND(o < per_object_.size());
  return per_object_[o].sticking;
}

Eigen::Vector2d AirForces::turbulence_state(size_t o) const {
  AIRTWIN_DEMAND(o < per_object_.size());
  return per_object_[o].eta;
}

void AirForces::apply(const mjModel* m, mjData* d) noexcept { run(m, d, false); }

void AirForces::apply_reference(const mjModel* m, mjData* d) noexcept { run(m, d, true); }

void AirForces::run(const mjModel* m, mjData* d, bool reference) noexcept {
  if (!fault_.empty()) return;
  // No air, a level floor and the contacts' own friction: nothing to do (the holding force
  // opposes air and slope only).
  const bool air = (field_ != nullptr || cfd_ != nullptr) && jet_level_ > 0.0;
  if (!air && m->opt.gravity[0] == 0.0 && m->opt.gravity[1] == 0.0 && !any_unload_) {
    // Nothing pulls: every object will stick once the air is back (a sliding one stops within
    // a step or two of kinetic friction anyway, and is released again by its speed).
    for (PerObject& po : per_object_) po.pull = po.speed = 0.0;
    return;
  }
  try {
    if (m != bound_model_) bind(m);
    compute_forces(m, d, air);
    for (size_t o = 0; o < objects_.size(); ++o) {
      const SceneObject& obj = objects_[o];
      for (size_t k = 0; k < obj.bodies.size(); ++k) {
        const int b = obj.bodies[k];
        const Eigen::Index col = static_cast<Eigen::Index>(first_body_[o] + k);
        const double fx = f_body_W_(0, col), fy = f_body_W_(1, col), fz = lift_body_[col];
        if (reference) {
          // Slow reference: MuJoCo's own Jacobian transpose at the body origin.
          const mjtNum force[3] = {fx, fy, fz};
          const mjtNum torque[3] = {0.0, 0.0, 0.0};
          mj_applyFT(m, d, force, torque, d->xpos + 3 * b, b, d->qfrc_passive);
        } else if (dofs_[col].free_dof >= 0) {
          // At a free joint's anchor: the force acts on its translational dofs alone.
          d->qfrc_passive[dofs_[col].free_dof] += fx;
          d->qfrc_passive[dofs_[col].free_dof + 1] += fy;
          d->qfrc_passive[dofs_[col].free_dof + 2] += fz;
        } else {
          // J^T F over the chain: column j of the point Jacobian is
          // cdof_lin_j + cdof_ang_j x (p - subtree_com(root)), as mj_jac builds it.
          const mjtNum* root_com = d->subtree_com + 3 * m->body_rootid[b];
          const double ox = d->xpos[3 * b] - root_com[0], oy = d->xpos[3 * b + 1] - root_com[1],
                       oz = d->xpos[3 * b + 2] - root_com[2];
          for (int j : dofs_[col].chain) {
            const mjtNum* c = d->cdof + 6 * j;
            const double jx = c[3] + (c[1] * oz - c[2] * oy);
            const double jy = c[4] + (c[2] * ox - c[0] * oz);
            const double jz = c[5] + (c[0] * oy - c[1] * ox);
            d->qfrc_passive[j] += jx * fx + jy * fy + jz * fz;
          }
        }
      }
    }
  } catch (const std::exception& e) {
    fault_ = std::string("air-force callback failed: ") + e.what();
  } catch (...) {
    fault_ = "air-force callback failed with an unknown exception";
  }
}

void AirForces::bind(const mjModel* m) {
  dofs_.assign(static_cast<size_t>(p_body_W_.cols()), BodyDofs{});
  for (size_t o = 0; o < objects_.size(); ++o) {
    const SceneObject& obj = objects_[o];
    for (size_t k = 0; k < obj.bodies.size(); ++k) {
      const int b = obj.bodies[k];
      AIRTWIN_DEMAND(b > 0 && b < m->nbody);
      BodyDofs& dofs = dofs_[first_body_[o] + k];
      const int j = m->body_jntadr[b];
      if (obj.bodies.size() == 1 && m->body_jntnum[b] == 1 && m->jnt_type[j] == mjJNT_FREE &&
          m->jnt_pos[3 * j] == 0 && m->jnt_pos[3 * j + 1] == 0 && m->jnt_pos[3 * j + 2] == 0) {
        dofs.free_dof = m->jnt_dofadr[j];
        continue;
      }
      // The dofs that move the body: its own and its ancestors', as mj_jac walks them.
      int body = b;
      while (body > 0 && m->body_dofnum[body] == 0) body = m->body_parentid[body];
      if (body <= 0) continue;
      for (int i = m->body_dofadr[body] + m->body_dofnum[body] - 1; i >= 0;
           i = m->dof_parentid[i]) {
        dofs.chain.push_back(i);
      }
    }
  }
  bound_model_ = m;
}

// The horizontal force on every body (f_body_W_) from the state in d; without `air`, only the
// holding force against the floor's slope.
void AirForces::compute_forces(const mjModel* m, const mjData* d, bool air) {
  const double scale = air ? jet_level_ * params_.field_scale : 0.0;  // J f: air-speed factor
  const double g_normal = std::abs(m->opt.gravity[2]);
  const Eigen::Vector2d g_floor_W(m->opt.gravity[0], m->opt.gravity[1]);
  const double b2 = params_.pressure_radius_m * params_.pressure_radius_m;
  const double push = scale * scale * params_.stagnation_pressure_pa;
  const double l2 = params_.extra_push_length_m * params_.extra_push_length_m;
  // sqrt(2e) / l: a(r) = A sqrt(2e) (r / l) exp(-(r / l)^2) peaks at A when r = l / sqrt(2).
  const double extra_push = scale * scale * params_.extra_push_mps2 *
                            std::sqrt(2.0 * std::exp(1.0)) / params_.extra_push_length_m;
  const double i_near = params_.turbulence_near, i_far = params_.turbulence_far;
  const double lt2 = params_.turbulence_length_m * params_.turbulence_length_m;

  // Every body's centre of mass and velocity, and the mean air velocity there, in one batch.
  for (size_t o = 0; o < objects_.size(); ++o) {
    const SceneObject& obj = objects_[o];
    for (size_t k = 0; k < obj.bodies.size(); ++k) {
      const int b = obj.bodies[k];
      const Eigen::Index col = static_cast<Eigen::Index>(first_body_[o] + k);
      p_body_W_(0, col) = d->xipos[3 * b];
      p_body_W_(1, col) = d->xipos[3 * b + 1];
      z_body_[col] = d->xipos[3 * b + 2];
      // The drag's velocity is that of the point it acts on (the body origin): then the drag
      // only ever takes energy out. Taken at the centre of mass while acting at the face, it
      // pumped energy into a tumbling tracer's spin until it flew off the floor.
      v_body_W_.col(col) = body_origin_velocity(m, d, b).head<2>();
    }
  }
  if (air && cfd_ != nullptr) {
    for (size_t o = 0; o < objects_.size(); ++o) {
      const CfdOrientedField& cfd = object_cfd_[o] != nullptr ? *object_cfd_[o] : *cfd_;
      const Eigen::Vector2d& s_W = cfd.stagnation_point();
      const double reach2 = cfd.pressure_radius_m() * cfd.pressure_radius_m();
      for (Eigen::Index col = static_cast<Eigen::Index>(first_body_[o]);
           col < static_cast<Eigen::Index>(first_body_[o + 1]); ++col) {
        const CfdSample a = cfd.at(p_body_W_.col(col), z_body_[col]);
        u_body_W_.col(col) = a.u_W + object_departure_[o];
        k_body_[col] = a.k;
        epsilon_body_[col] = a.epsilon;
        // The pressure only matters near s; farther out it is not looked up.
        if ((p_body_W_.col(col) - s_W).squaredNorm() < reach2) {
          grad_p_body_W_.col(col) = cfd.pressure_gradient_at(p_body_W_.col(col), z_body_[col]);
        } else {
          grad_p_body_W_.col(col).setZero();
        }
      }
    }
  } else if (air) {
    field_->velocities(p_body_W_, u_body_W_);
    if (any_object_air_) {
      // The transport lag: objects still in an older orientation's air take it from there.
      for (size_t o = 0; o < objects_.size(); ++o) {
        if (object_rays_[o] == nullptr) continue;
        for (size_t col = first_body_[o]; col < first_body_[o + 1]; ++col) {
          const Eigen::Index c = static_cast<Eigen::Index>(col);
          u_body_W_.col(c) = object_rays_[o]->velocity(p_body_W_.col(c));
        }
      }
    }
  }

  for (size_t o = 0; o < objects_.size(); ++o) {
    const SceneObject& obj = objects_[o];
    PerObject& po = per_object_[o];
    const Eigen::Index first = static_cast<Eigen::Index>(first_body_[o]);
    const Eigen::Index n = static_cast<Eigen::Index>(obj.bodies.size());
    // The stagnation point of the air this object is in.
    const Eigen::Vector2d s_W =
        !air              ? Eigen::Vector2d::Zero()
        : cfd_ != nullptr ? (object_cfd_[o] != nullptr ? *object_cfd_[o] : *cfd_).stagnation_point()
                          : (object_rays_[o] != nullptr ? object_rays_[o]->stagnation_point()
                                                        : field_->stagnation_point());

    // The object's centre and velocity (area-weighted), and its turbulent air velocity.
    Eigen::Vector2d centre = Eigen::Vector2d::Zero(), v_obj = Eigen::Vector2d::Zero();
    for (Eigen::Index k = 0; k < n; ++k) {
      centre += obj.area_share[k] * p_body_W_.col(first + k);
      v_obj += obj.area_share[k] * v_body_W_.col(first + k);
    }
    double sigma = 0.0;
    if (air && cfd_ != nullptr) {
      // The CFD's turbulence at the object: sigma = sqrt(2k/3), T_L = C_L k / epsilon.
      double k = 0.0, epsilon = 0.0;
      for (Eigen::Index j = 0; j < n; ++j) {
        k += obj.area_share[j] * k_body_[first + j];
        epsilon += obj.area_share[j] * epsilon_body_[first + j];
      }
      sigma = std::sqrt(2.0 * std::max(k, 0.0) / 3.0);
      if (k > 0.0 && epsilon > 0.0) {
        if (params_.turbulence_swept) {
          // The eddies die after T_L and are swept past the object at its speed relative to the
          // mean air (models/turbulence_time.h): a tracer held by friction in 3 m/s of air sees
          // them for less than half of T_L.
          Eigen::Vector2d u_mean = Eigen::Vector2d::Zero();
          for (Eigen::Index j = 0; j < n; ++j) {
            u_mean += obj.area_share[j] * u_body_W_.col(first + j);
          }
          const double sweep_mps = (scale * turned(u_mean) - v_obj).norm();
          po.decay = std::exp(-timestep_s_ /
                              swept_integral_time_s(params_.lagrangian_time_factor * k / epsilon,
                                                    sweep_mps, k, epsilon));
        } else {
          po.decay = std::exp(-timestep_s_ * epsilon / (params_.lagrangian_time_factor * k));
        }
        po.kick = std::sqrt(std::max(0.0, 1.0 - po.decay * po.decay));
      }
    } else {
      const double r_obj2 = (centre - s_W).squaredNorm();
      sigma = params_.turbulence_reference_speed_mps *
              (i_far + (i_near - i_far) * std::exp(-r_obj2 / lt2));
    }
    const Eigen::Vector2d u_turbulent = sigma * po.eta;

    // Drag and pressure pushes on each body, by its area share.
    Eigen::Vector2d total = Eigen::Vector2d::Zero();
    double lift_total = 0.0;
    for (Eigen::Index k = 0; k < n; ++k) lift_body_[first + k] = 0.0;
    for (Eigen::Index k = 0; k < n && !air; ++k) f_body_W_.col(first + k).setZero();
    for (Eigen::Index k = 0; k < n && air; ++k) {
      const Eigen::Index col = first + k;
      const double w = obj.area_share[k];
      const Eigen::Vector2d p = p_body_W_.col(col), v = v_body_W_.col(col);
      // Mean air (turned by the flow deflection) plus turbulence, times the jet level and scale.
      const Eigen::Vector2d mean = u_body_W_.col(col);
      const Eigen::Vector2d u = scale * (turned(mean) + u_turbulent);
      Eigen::Vector2d f;
      if (po.physical) {
        // 1/2 rho C_D(Re) A |u_rel| u_rel, C_D(Re) = C_D + 24 / Re.
        const Eigen::Vector2d u_rel = u - v;
        f = w * (po.quadratic * u_rel.norm() + po.viscous) * u_rel;
        lift_body_[col] = w * po.lift * u_rel.squaredNorm();
        lift_total += lift_body_[col];
      } else if (po.tangent_speed > 0.0) {
        // linearised_drag: c (k u - v) = c w is the tangent at |w| = w0 of the quadratic
        // (c / 2 w0) |w| w, less its intercept c w0 / 2 along w (taken from the friction below:
        // the contact carries 1 - share of the weight, so its friction is (1 - share) mu_k m g).
        const Eigen::Vector2d w_rel = po.air_gain * u - v;
        const double n_rel = w_rel.norm();
        f = n_rel >= po.tangent_speed
                ? w * (po.drag_coefficient - po.intercept_force / n_rel) * w_rel
                : w * (0.5 * po.drag_coefficient / po.tangent_speed) * n_rel * w_rel;
      } else {
        // eq. (8) as physics: F = c (k u - v).
        f = w * po.drag_coefficient * (po.air_gain * u - v);
      }
      if (po.extra_quadratic > 0.0) {
        const Eigen::Vector2d u_rel = u - v;
        f += w * obj.mass_kg * po.extra_quadratic * u_rel.norm() * u_rel;
      }
      if (po.extra_lift > 0.0) {
        // The air_lift effect: the fraction k |u_rel|^2 of the body's share of the weight.
        const double lift = w * obj.mass_kg * po.extra_lift * g_normal * (u - v).squaredNorm();
        lift_body_[col] += lift;
        lift_total += lift;
      }
      const Eigen::Vector2d from_s = p - s_W;
      const double r2 = from_s.squaredNorm();
      if (cfd_ != nullptr) {
        // The CFD's own pressure: -V grad p, p = rho (p / rho) of the CFD, times (J f)^2.
        if (params_.stagnation_pressure_pa > 0.0) {
          f -= w * po.pressure_volume * air_density_ * scale * scale * grad_p_body_W_.col(col);
        }
      } else if (push > 0.0 && r2 > 0.0) {
        // -dp/dr along the unit radial direction: 2 r / b^2 p exp(-r^2/b^2) * (from_s / r).
        f += w * po.pressure_volume * push * (2.0 / b2) * std::exp(-r2 / b2) * from_s;
      }
      if (extra_push > 0.0 && r2 > 0.0) {
        // The pressure_gradient effect: A sqrt(2e) (r / l) exp(-(r/l)^2) along from_s / r.
        f += w * obj.mass_kg * extra_push * std::exp(-r2 / l2) * from_s;
      }
      f_body_W_.col(col) = f;
      total += f;
    }

    // linearised_drag: the friction that eq. (8)'s xi3 held for the drag's intercept is not the
    // contact's, jet or no jet.
    for (Eigen::Index k = 0; k < n && po.unload_share > 0.0; ++k) {
      const double unload = obj.area_share[k] * po.unload_share * obj.mass_kg * g_normal;
      lift_body_[first + k] += unload;
      lift_total += unload;
    }

    // Static friction: a sticking object is held against the whole pull (the air and the
    // floor's slope), up to mu_s (m g - L) (the lift unloads the contact), so that MuJoCo's soft
    // kinetic contacts, which creep under a steady pull, have nothing left to hold.
    const Eigen::Vector2d held = total + obj.mass_kg * g_floor_W;
    const double held_norm = held.norm();
    po.pull = held_norm;
    po.load = std::max(0.0, g_normal - lift_total / obj.mass_kg);
    po.speed = v_obj.norm();
    if (po.sticking && held_norm > 0.0) {
      const double most = (po.extra_static + po.kinetic) * po.load;
      const Eigen::Vector2d hold = -(std::min(held_norm, most) / held_norm) * held;
      for (Eigen::Index k = 0; k < n; ++k) f_body_W_.col(first + k) += obj.area_share[k] * hold;
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
