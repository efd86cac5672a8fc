#pragma once
// What a twin run is made of, as plain data: the objects of one scenario (SceneSpec, per run) and
// the fixed physical description of the object types and the room (SceneParameters).
//
// The object-type defaults come from the paper: sizes and masses from sections II-B and IV-C, and
// the drag and friction numbers from the identified dynamics of eq. (8) (section IV-B/C) read as
// physics:
//   m dv/dt = c (k u_air - v) - mu_k m g   (drag on a scaled relative air speed, Coulomb friction)
//   <=> dv/dt = -(c/m) v + (c/m) k u_air - mu_k g = xi1 v + xi2 u_air + xi3
// so  c/m = -xi1,  k = xi2 / (-xi1),  mu_k = -xi3 / g.
// k > 1 for the tracer (1.60): the object reacts as if the air were faster than the field model's
// speed at 1.5 cm. eq. (8) is a linear fit of a nonlinear (roughly quadratic) drag around the
// operating range, and a linearised quadratic drag is exactly such an affine law whose air and
// object coefficients need not match; the twin keeps the fit's structure so that identification
// on twin data can recover eq. (8). The defaults use calibrated triples (kTracerTwinPhysics,
// kCottonTwinPhysics below), not the paper's coefficients themselves.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "models/object_dynamics.h"

namespace airtwin {

/// The twin's physics triples (x1, x2, x3): drag rate c/m = -x1, air gain k = x2 / -x1, kinetic
/// friction mu_k = -x3 / g. Calibrated (airtwin calibrate-dynamics, docs/twin.md) so that the
/// paper's identification on Appendix D data collected in the twin returns the paper's eq. (8)
/// coefficients (kTracerDynamics, kCottonDynamics): turbulence and the soft contacts make SINDy
/// see a weaker drag than the physics has (the tracer's -2.98 1/s reads as -2.66).
inline constexpr ObjectDynamics kTracerTwinPhysics{-2.982, 4.415, -8.789};
inline constexpr ObjectDynamics kCottonTwinPhysics{-4.455, 3.616, -4.270};

/// The object kinds the twin can build.
enum class ObjectType { kTracer, kCotton };

/// "tracer" or "cotton".
const char* object_type_name(ObjectType type);

/// How the air pushes an object (sim/air_forces.h).
enum class DragLaw {
  /// F = c (k u - v): eq. (8) read as physics (drag_rate_per_s, air_gain).
  kLinear,
  /// F = 1/2 rho C_D(Re) A |u - v| (u - v), C_D(Re) = drag_coefficient + 24 / Re, Re = |u - v| L /
  /// nu: quadratic form drag with the viscous (Stokes) part that takes over at low Re; and a lift
  /// 1/2 rho C_L A_base |u - v|^2 that unloads the contact (a body on a floor in shear flow).
  kPhysical,
};

/// Physical description of one object type: body, contact and aerodynamics.
struct ObjectTypeParameters {
  double diameter_m = 0.0;  ///< footprint diameter (m)
  double mass_kg = 0.0;     ///< total mass (kg)
  /// Kinetic (Coulomb) friction coefficient against the floor, set on the MuJoCo contacts.
  double kinetic_friction = 0.0;
  /// Static / kinetic friction ratio (>= 1). The part above kinetic is applied by the air-force
  /// callback as a holding force on an object that sticks (sim/air_forces.h): one slower than
  /// `stiction_speed_mps` whose pull has not passed static friction since it came to rest.
  double static_friction_ratio = 1.0;
  double stiction_speed_mps = 0.005;  ///< speed (m/s) below which the object counts as sticking
  /// Drag rate c/m (1/s) of F = c (k u_air - v).
  double drag_rate_per_s = 0.0;
  /// Air-speed gain k (dimensionless) of F = c (k u_air - v).
  double air_gain = 0.0;
  /// Volume (m^3) on which the stagnation pressure gradient acts (F = -grad p * V).
  double pressure_volume_m3 = 0.0;
  /// The force law; kLinear uses drag_rate_per_s and air_gain, kPhysical the three below.
  DragLaw drag_law = DragLaw::kLinear;
  double drag_coefficient = 0.0;  ///< C_D at high Re (dimensionless, on frontal_area_m2)
  double frontal_area_m2 = 0.0;   ///< A: the area the horizontal air meets (m^2)
  double drag_length_m = 0.0;     ///< L of Re (m)
  /// mu_k with physical drag: a measured-kind value, not eq. (8)'s -xi3 / g.
  double physical_kinetic_friction = 0.0;
  /// Static / kinetic friction ratio under DragLaw::kPhysical (eq. (8)'s law has none: its xi3
  /// is one friction fitted on data that include the starts).
  double physical_static_friction_ratio = 1.0;
  /// C_L of the physical law's lift, on the footprint area pi (diameter / 2)^2 (dimensionless).
  double lift_coefficient = 0.0;

  // Effects on objects of this type (sim/effects.h: NAME or NAME@TYPE), off by default.
  /// quadratic_drag's C_q (1/m): an extra acceleration C_q |u_rel| u_rel, under either law.
  double extra_quadratic_drag_per_m = 0.0;
  /// air_lift's k (s^2/m^2): an upward lift k m g |u_rel|^2 (by area share), under either law and
  /// on top of the physical law's own: the contact, so the friction, falls by k |u_rel|^2.
  double extra_lift_s2pm2 = 0.0;
  /// linearised_drag's share s in [0, 1) (0: off): under eq. (8)'s law the drag c (k u - v) = c w
  /// becomes the quadratic (c / 2 w0) |w| w that it is the tangent of at |w| = w0 =
  /// 2 s mu_k g / c, less the tangent's intercept s mu_k g along w for |w| >= w0, and the contact
  /// carries 1 - s of the weight, so the friction is (1 - s) mu_k m g. InputError under the
  /// physical law.
  double drag_intercept_share = 0.0;

  /// Switches to DragLaw::kPhysical and its friction (physical_kinetic_friction,
  /// physical_static_friction_ratio).
  void use_physical_drag();

  /// The mapping of eq. (8) to drag and friction described in the header comment, for a body of
  /// the given diameter and mass; g in m/s^2.
  static ObjectTypeParameters from_dynamics(const ObjectDynamics& xi, double diameter_m,
                                            double mass_kg, double gravity_mps2 = 9.81);
  /// Polystyrene hemisphere, 3 cm, 0.16 g (section II-B), eq. (8) tracer coefficients, static
  /// friction 1.2 x kinetic (foam on a smooth floor), pressure volume = the solid hemisphere.
  static ObjectTypeParameters tracer();
  /// Cotton wad, ~5 cm, 0.22 g (section IV-C), eq. (8) cotton coefficients, static friction
  /// 1.3 x kinetic (fibres catch), pressure volume of a porous wad (a tenth of its envelope: air
  /// passes through the fibres, so the pressure difference acts on little of it).
  static ObjectTypeParameters cotton();

  /// The eq. (8) coefficients these parameters reproduce on a flat floor (the inverse mapping).
  ObjectDynamics dynamics(double gravity_mps2 = 9.81) const;
};

/// One object of a scenario.
struct ObjectSpec {
  std::string id;                 ///< unique, non-empty; names the object in messages and output
  std::string type;               ///< "tracer" | "cotton"
  Eigen::Vector2d p_W{0.0, 0.0};  ///< start position on the floor (m), world frame
  std::optional<double> yaw_rad;  ///< start heading (rad); unset: drawn from the twin's seed
  /// This object's own physics (sim/physics_variation.h: objects of one type that differ);
  /// unset: its type's in SceneParameters. Its diameter must be the type's: the geometry is.
  std::optional<ObjectTypeParameters> physics = std::nullopt;
};

/// The objects of one run. `source` names the scenario in error messages ("scenes/line.yaml").
struct SceneSpec {
  std::vector<ObjectSpec> objects;
  std::string source = "scene";
};

/// The fixed description of the twin's world (not per run).
struct SceneParameters {
  /// Physics step (s); 1-2.5 ms are stable. 2.5 ms: the twin's speed target (docs/twin.md) and
  /// a whole number of steps per 40 Hz camera frame.
  double timestep_s = 0.0025;
  /// MuJoCo's impratio: how much harder the friction constraints are than the normal ones
  /// (elliptic cones). MuJoCo's soft friction acts like a damper at low slip speeds, so an object
  /// creeps where Coulomb friction would stop it. 1 (MuJoCo's default) keeps sliding isotropic:
  /// 10 made friction more Coulomb-like but let a sliding tracer wander ~6 mm off its ray and
  /// ignore a 3 deg slope's sideways pull. With the calibrated turbulence, identification on twin
  /// data finds eq. (8)'s structure at 1, 3 and 10 alike (docs/twin.md, calibration).
  double friction_impedance_ratio = 1.0;
  /// MuJoCo's integrator: false, explicit Euler (every calibration and figure of docs/twin.md);
  /// true, "implicit" (velocity-implicit with the bias forces' derivative), ~20 % slower, which
  /// survives a tracer tumbling at hundreds of rad/s where Euler's gyroscopic term gains energy
  /// until the twin's runaway check stops the run (docs/twin.md, "Left for later").
  bool implicit_integrator = false;
  double floor_half_size_m = 2.0;      ///< the floor plane spans [-h, h]^2 (m) around the origin
  double air_density_kgpm3 = 1.2;      ///< rho of the room's air (20 C, sea level)
  double air_viscosity_m2ps = 1.5e-5;  ///< nu, kinematic
  double nozzle_height_m = 1.43;       ///< h: tilt shaft and nozzle exit above the floor (m)
  double camera_height_m = 3.2;        ///< top camera above the floor (m)
  double camera_half_view_m = 1.35;    ///< half the floor width the top camera sees (m)
  /// A floor tilted by this (rad, the floor_slope effect; 0 = level). The world frame stays the
  /// floor's frame (camera, field, positions); gravity tilts instead, with in-plane part
  /// g sin(slope) toward floor_slope_direction_rad (from +x, counter-clockwise).
  double floor_slope_rad = 0.0;
  double floor_slope_direction_rad = 0.0;  ///< downhill direction in the floor plane (rad)
  int camera_resolution_px = 1024;         ///< square offscreen image (px)
  ObjectTypeParameters tracer = ObjectTypeParameters::tracer();
  ObjectTypeParameters cotton = ObjectTypeParameters::cotton();
  /// Cotton shape: relative spread of the wad's per-axis extents and of each element's radius
  /// around the nominal sphere (0.2 = +-20 %), drawn from the twin's seed per object.
  double cotton_irregularity = 0.2;

  /// Gravity (m/s^2) in the floor's frame: 9.81 m/s^2 tilted by the floor slope.
  Eigen::Vector3d gravity_W() const;

  const ObjectTypeParameters& of(ObjectType type) const {
    return type == ObjectType::kTracer ? tracer : cotton;
  }
};

}  // namespace airtwin
