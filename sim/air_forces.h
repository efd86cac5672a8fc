#pragma once
// The air's push on every object body, applied through MuJoCo's passive-force callback.
//
// Per body b of object o (share w_b of o's horizontally projected area, sim/scene_builder.h), at
// the body's centre of mass p (floor plane), with v the velocity of the point the force acts on:
//
//   drag (the physics behind eq. 8, sim/scene_spec.h):
//     F_D = w_b c_o (k_o u(p) - v),   c_o = m_o * drag_rate_o,   k_o = air_gain_o
//     u(p) = J (v_air(p) + u'_o(t)):  v_air from the analytical field (section III) at the nozzle's
//     effective orientation, J the jet level (sim/nozzle_actuator.h), u'_o the turbulence.
//   turbulence near s (Appendix C: intensity up to ~10 % near s):
//     u'_o(t) = sigma(r) eta_o(t), eta_o two independent Ornstein-Uhlenbeck processes of unit
//     variance and correlation time turbulence_time_s, one pair per object, seeded;
//     sigma(r) = U_ref (I_far + (I_near - I_far) exp(-(r / L_t)^2)), r = |p_o - s|.
//     Defaults: U_ref 3.4 m/s (the paper's peak air speed), I_near 5 %, I_far 1.5 %, L_t 0.15 m,
//     correlation time 0.05 s (integral length ~0.1 m / speed ~2 m/s).
//   pressure-gradient push near s (the F_PG of eq. 4 that eq. 8 drops):
//     stagnation pressure p(r) = J^2 p_s exp(-(r / b)^2), F_PG = w_b V_o (-dp/dr) (radial, outward)
//     = w_b V_o J^2 p_s (2 r / b^2) exp(-(r / b)^2), largest at r = b / sqrt(2).
//     Defaults: p_s = 11 Pa = rho U^2 / 2 with U = 4.3 m/s, the free-jet centreline speed at the
//     floor (shared/notes/physics.md); b = 0.06 m, so the push peaks 4 cm from s and is gone by
//     ~15 cm. For the tracer (V = 7.1e-6 m^3) the peak is 1.1 mN, 7 m/s^2: below its friction.
//   static friction: kinetic friction comes from MuJoCo's contacts (mu_k per type). An object
//     that sticks is held by a force opposing the sum of the forces above (the pull P), at most
//     mu_s m_o g: the whole of it, since MuJoCo's soft contacts creep under a steady pull.
//     Coulomb's hysteresis decides which do, once per step (advance_friction): an object sticks
//     while |v_o| < v_stick and |P| <= mu_s m_o g; once released it slides on kinetic friction
//     alone until it is back under v_stick with |P| < mu_k m_o g. Objects start sticking.
// Forces are horizontal and act at each body's frame origin: the centre of a wad element, the
// centre of a tracer's flat face. At the face the air adds no pitching moment; applied at the
// tracer's centre of mass (5.6 mm up) it made the disc rock and hop on MuJoCo's soft contacts.
// The drag's v is that point's velocity too, so the drag never does work on a body's spin (with
// the centre's velocity instead, a tumbling tracer gained energy until it flew off the floor).
//
// The CFD's air (set_air with a CfdOrientedField, models/cfd_field.h) replaces the analytical
// field and the hand-set turbulence above: v_air(p) is the CFD's mean velocity at the body's
// centre of mass (its height included), and the turbulence comes from the CFD's k and epsilon at
// the object (area-weighted over its bodies): sigma = sqrt(2 k / 3) per horizontal component
// (isotropic), correlation time T_L = C_L k / epsilon with C_L = 0.15, the Lagrangian time scale
// of random-walk particle dispersion in k-epsilon flows (ANSYS Fluent Theory Guide, "Stochastic
// Tracking"). Each object's OU process then decays with its own T_L, taken where it last was.
// k and epsilon are those of the full jet; sigma is scaled by J f like the mean air. The pressure
// push is the CFD's too: F_PG = -w_b V_o rho J^2 f^2 grad(p / rho) with the CFD's kinematic
// pressure at the body (its height included; the stagnation pressure there is ~17 Pa, half of it
// ~10 cm from s at tilt 0), instead of the Gaussian above (p_s and b describe the analytical
// air's push only; p_s = 0 switches either push off).
//
// Physical drag (ObjectTypeParameters::drag_law = kPhysical, sim/scene_spec.h) replaces the drag
// above on every body: F_D = w_b (1/2 rho C_D A |u_rel| + 12 rho A nu / L) u_rel, u_rel = u(p) - v,
// i.e. 1/2 rho C_D(Re) A |u_rel| u_rel with C_D(Re) = C_D + 24 / Re, Re = |u_rel| L / nu; no
// parameter of it is an eq. (8) coefficient. It adds a lift on each body, upward at the body
// origin: L = w_b 1/2 rho C_L A_base |u_rel|^2 with A_base the footprint pi (diameter / 2)^2, which
// unloads the contact, so MuJoCo's friction falls with it; the static holding force above is
// mu_s (m g - L) then.
//
// Effects (sim/effects.h; all off by default, docs/twin.md): field_scale f multiplies the air
// speed (mean and turbulent, so the stagnation pressure by f^2); flow_deflection turns the mean
// air velocity by a fixed angle (counter-clockwise positive) at the same speed; quadratic_drag
// adds a w_b m_o C_q |u_rel| u_rel with u_rel = u(p) - v; pressure_gradient adds a radial push of
// peak acceleration A at r = l / sqrt(2): a(r) = J^2 f^2 A sqrt(2e) (r / l) exp(-(r / l)^2);
// air_lift adds an upward w_b k m_o g |u_rel|^2 that unloads the contact as the physical lift does;
// linearised_drag (eq. (8)'s law only) bends the drag c w, w = k u - v, into the quadratic it is
// the tangent of at |w| = w0 and takes the tangent's intercept c w0 / 2 from the friction by
// unloading the contact by that share of the weight (a lower mu_k on the contact would need the
// model rebuilt; the unloaded contact's friction is the same).
// Static friction holds against the in-plane part of gravity too (a sloped floor).
//
// Speed. The generalised force of a body is written straight into qfrc_passive: for a one-body
// object on a free joint anchored at the body origin (a tracer) the force at that origin is just
// (F_x, F_y) on the joint's two horizontal translational dofs (no torque: the point is the
// anchor); for a body inside a tree (a wad element) it is J^T F over the dofs of its chain only,
// with J from mjData::cdof as mj_jac builds it. mj_applyFT would do the same with dense 3 x nv
// Jacobians. The field is evaluated for all bodies in one batch; nothing is allocated per step.
//
// Threading. mjcb_passive is one process-wide pointer; this file is its only owner. It points to a
// dispatcher that looks up the AirForces registered *on the calling thread* (thread_local, by an
// AirForcesScope around mj_step) and checks that MuJoCo called it for that scope's model; any
// other call (another thread's bare model, an mj_forward outside a scope) gets no air force. So
// any number of twins can step concurrently, one per thread, without sharing anything mutable.
// Nothing here throws into MuJoCo: a fault inside the callback is recorded and the twin reports it
// after mj_step returns.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include "common/random_stream.h"
#include "models/air_field.h"
#include "models/cfd_field.h"
#include "sim/scene_builder.h"
#include "sim/scene_spec.h"

namespace airtwin {

/// The truths the controller's model lacks (besides servo, delay and ramp, sim/nozzle_actuator.h).
struct AirForceParameters {
  /// Intensity at s (fraction of the reference speed). The paper's "up to ~10 %" is the peak of
  /// a fluctuating intensity; 5 % of U_ref as the standard deviation of the forcing reproduces its
  /// repeatability (7.7 %) and end-position errors (9 %, 19.3 %) best (docs/twin.md, calibration).
  double turbulence_near = 0.05;
  double turbulence_far = 0.015;                ///< intensity far from s
  double turbulence_length_m = 0.15;            ///< L_t (m): where near turns into far
  double turbulence_reference_speed_mps = 3.4;  ///< U_ref (m/s)
  double turbulence_time_s = 0.05;              ///< correlation time (s) of eta
  /// p_s (Pa) of the analytical air's push; 0 switches the push off (the CFD's too)
  double stagnation_pressure_pa = 11.0;
  double pressure_radius_m = 0.06;  ///< b (m)
  /// C_L: the turbulence's correlation time under the CFD's air is C_L k / epsilon.
  double lagrangian_time_factor = 0.15;
  /// Under the CFD's air, the eddies an object feels are also swept past it at its speed
  /// relative to the mean air, so their correlation time is 1 / (1 / T_L + |u - v| / L11)
  /// (models/turbulence_time.h: the crossing-trajectories effect); false: T_L alone
  /// (docs/twin.md, "Turbulence swept past the objects").
  bool turbulence_swept = true;

  // Effects (sim/effects.h), neutral by default.
  double field_scale = 1.0;           ///< factor f on the air speed (> 0)
  double flow_deflection_rad = 0.0;   ///< mean air velocity turned by this (rad, CCW +)
  double extra_push_mps2 = 0.0;       ///< A (m/s^2): peak of the extra radial push
  double extra_push_length_m = 0.15;  ///< l (m): its decay length (peak at l / sqrt(2))
  // The objects' own effects (quadratic_drag, air_lift, linearised_drag) are their types'
  // (ObjectTypeParameters, sim/scene_spec.h).

  /// No turbulence, no pressure push: the deterministic drag of eq. (8) only.
  static AirForceParameters none();
  /// Throws InputError naming the field unless every value is finite and in range.
  void validate() const;
};

class AirForces {
 public:
  /// `objects` index the bodies of the compiled model this will push; `seed` seeds the turbulence
  /// (one stream per object); `timestep_s` is the step of advance_turbulence().
  AirForces(const AirForceParameters& params, const SceneParameters& scene,
            std::vector<SceneObject> objects, uint64_t seed, double timestep_s);

  /// The analytical field (at the effective orientation) and jet level (0..1) for the coming step.
  void set_air(const OrientedField& field, double jet_level);
  /// The same with the CFD's air (its mean velocity and turbulence, see the top of this file).
  void set_air(const CfdOrientedField& field, double jet_level);
  /// The mean air (m/s, world frame) at floor point p_W (m) and height z_m (m; the CFD's air
  /// depends on it, the analytical field does not) as the drag sees it before turbulence: the
  /// common air of set_air (not an object's own lagged air), turned by the flow deflection, times
  /// the jet level and the field scale. Zero before set_air. For pictures (the live viewer's
  /// arrows); the forces do not call it.
  Eigen::Vector2d mean_air(const Eigen::Vector2d& p_W, double z_m) const;
  /// In the CFD's air, object o feels `field` instead of the common air until
  /// clear_object_air(): the wall jet's transport lag gives each object the orientation whose air
  /// has reached it (sim/air_transport.h). `field` must outlive the next apply().
  void set_object_air(size_t o, const CfdOrientedField& field);
  /// In the analytical air, the same: object o feels `rays` (an orientation's analytical air,
  /// read along the two profiles around each of its bodies) instead of the common one until
  /// clear_object_air() (the transport_lag effect).
  void set_object_air(size_t o, const OrientedRays& rays);
  /// In the CFD's air, object o's bodies feel `departure` (m/s, world frame, before the jet
  /// level and field scale) added to the air of its field until clear_object_air(): the wall
  /// jet still forming after the reached orientation changed (sim/air_transport.h).
  void set_object_air_departure(size_t o, const Eigen::Vector2d& departure);
  /// Every object feels the common air again, with no departure.
  void clear_object_air();
  /// The mean air object o feels at floor point p_W and height z_m (m/s, world frame, before
  /// turbulence): its own field and departure, turned, times the jet level and field scale.
  Eigen::Vector2d object_mean_air(size_t o, const Eigen::Vector2d& p_W, double z_m) const;
  /// Advances each object's turbulence by one timestep (call once per physics step).
  void advance_turbulence();
  /// Decides which objects stick during the coming step from the pull and speed of the last
  /// apply() (call once per physics step, before it; see static friction at the top).
  void advance_friction();
  /// Whether object o sticks (its static friction holds) during the coming step.
  bool sticking(size_t o) const;
  /// Adds the air forces of the current state to d->qfrc_passive. Called by the dispatcher from
  /// inside mj_step; never throws (a fault is recorded, see fault()). The first call binds the
  /// object bodies to `m`'s dofs; later calls must pass the same model.
  void apply(const mjModel* m, mjData* d) noexcept;
  /// The same forces through mj_applyFT (the slow reference the fast path is tested against).
  void apply_reference(const mjModel* m, mjData* d) noexcept;

  /// The unit-variance turbulence state eta_o of object o (u'_o = sigma(r) eta_o).
  Eigen::Vector2d turbulence_state(size_t o) const;
  /// Most bodies one object may have.
  static constexpr size_t kMaxBodiesPerObject = kMaxObjectBodies;
  /// Empty, or what went wrong inside the callback (the first fault only).
  const std::string& fault() const { return fault_; }
  const std::vector<SceneObject>& objects() const { return objects_; }
  const AirForceParameters& parameters() const { return params_; }

 private:
  struct PerObject {
    bool physical;            // DragLaw::kPhysical
    double quadratic;         // 1/2 rho C_D A (kg/m)
    double viscous;           // 12 rho A nu / L (kg/s): the 24/Re part, linear in u - v
    double lift;              // 1/2 rho C_L A_base (kg/m): lift = lift |u - v|^2, upward
    double drag_coefficient;  // c_o (kg/s)
    double air_gain;          // k_o
    double tangent_speed;     // w0 (m/s) of linearised_drag, 0: off
    double intercept_force;   // m_o c_o w0 / 2 (N): the tangent's intercept as a force
    double unload_share;      // the share of the weight the contact is unloaded by
    double extra_quadratic;   // quadratic_drag's C_q (1/m)
    double extra_lift;        // air_lift's k (s^2/m^2)
    double pressure_volume;   // V_o (m^3)
    double extra_static;      // (mu_s - mu_k) m_o (kg)
    double kinetic;           // mu_k m_o (kg), times g gives the kinetic friction
    double stiction_speed;    // v_stick (m/s)
    bool sticking;            // static friction holds during this step
    double pull;              // |P| at the last apply (N)
    double load;              // the contact's load per unit mass at the last apply (m/s^2)
    double speed;             // |v_o| at the last apply (m/s)
    Eigen::Vector2d eta;      // OU state, unit variance per component
    double decay;             // eta's decay over one step (exp(-dt / T_L) under the CFD's air)
    double kick;              // sqrt(1 - decay^2): the new noise's weight, unit variance kept
  };
  // How one body's force reaches qfrc_passive (bound to a model on the first apply()).
  struct BodyDofs {
    int free_dof = -1;       // >= 0: translational dofs of a free joint anchored at the origin
    std::vector<int> chain;  // otherwise: every dof from the body up to its root
  };
  // `mean` turned by the flow deflection (counter-clockwise positive).
  Eigen::Vector2d turned(const Eigen::Vector2d& mean) const {
    return {cos_deflection_ * mean.x() - sin_deflection_ * mean.y(),
            sin_deflection_ * mean.x() + cos_deflection_ * mean.y()};
  }
  void bind(const mjModel* m);
  void compute_forces(const mjModel* m, const mjData* d, bool air);
  void run(const mjModel* m, mjData* d, bool reference) noexcept;

  AirForceParameters params_;
  std::vector<SceneObject> objects_;
  std::vector<PerObject> per_object_;
  std::vector<RandomStream> streams_;      // turbulence, one per object
  const OrientedField* field_ = nullptr;   // the analytical air, or
  const CfdOrientedField* cfd_ = nullptr;  // the CFD's
  // Per object in the CFD's air: its own air (set_object_air), or null for the common one.
  std::vector<const CfdOrientedField*> object_cfd_;
  // Per object in the analytical air: its own air (set_object_air), or null for the common one.
  std::vector<const OrientedRays*> object_rays_;
  std::vector<Eigen::Vector2d> object_departure_;  // per object (set_object_air_departure)
  bool any_object_air_ = false;
  bool any_unload_ = false;  // some object has linearised_drag (its contact unloaded in still air)
  double jet_level_ = 0.0;
  double timestep_s_ = 0.0;
  double ou_decay_ = 0.0, ou_kick_ = 0.0;  // eta <- decay eta + kick N(0, 1), the analytical air's
  double cos_deflection_ = 1.0, sin_deflection_ = 0.0;
  // Per body, flattened over the objects (object o's bodies start at first_body_[o]).
  std::vector<size_t> first_body_;
  const mjModel* bound_model_ = nullptr;
  std::vector<BodyDofs> dofs_;
  double air_density_ = 0.0;  // rho (kg/m^3): the CFD's kinematic pressure times it is Pa
  Eigen::Matrix2Xd p_body_W_, v_body_W_, u_body_W_, f_body_W_;  // scratch, sized once
  Eigen::Matrix2Xd grad_p_body_W_;  // the CFD's kinematic pressure gradient (m/s^2)
  Eigen::VectorXd z_body_, k_body_, epsilon_body_;
  Eigen::VectorXd lift_body_;  // the upward lift on each body (N), physical drag only
  std::string fault_;
};

/// Registers `forces` as the air of `model` on the calling thread for the scope's lifetime (and
/// installs the dispatcher into mjcb_passive on first use). Scopes nest; the innermost wins.
class AirForcesScope {
 public:
  AirForcesScope(const mjModel* model, AirForces* forces);
  ~AirForcesScope();
  AirForcesScope(const AirForcesScope&) = delete;
  AirForcesScope& operator=(const AirForcesScope&) = delete;

 private:
  const mjModel* previous_model_;
  AirForces* previous_forces_;
};

}  // namespace airtwin
