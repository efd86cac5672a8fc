#pragma once
// The MuJoCo twin of the rig: a scene of tracers and cotton wads on the floor, the nozzle's servos
// and jet (sim/nozzle_actuator.h), and the air forces (sim/air_forces.h) of the jet's CFD
// (models/cfd_field.h) or, for comparison, of the controller's analytical field (eqs. 1-3),
// stepped at a fixed physics timestep.
//
// One Twin owns its mjModel and mjData; nothing mutable is shared between twins, so independent
// twins can run in different threads at once (the passive callback dispatches per thread). Same
// SceneSpec, TwinParameters, field model and seed -> bit-identical states.
//
// One step, in order: the actuator advances (servos, delay line, jet level); the rig's joints are
// set to the actual orientation; the air's field (the CFD's, or else the analytical one) is
// (re)built at the effective orientation; turbulence advances; mj_step runs with this twin's air
// forces registered; the state is checked.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include "models/air_field.h"
#include "models/cfd_field.h"
#include "sim/air_forces.h"
#include "sim/air_transport.h"
#include "sim/mujoco_runtime.h"
#include "sim/nozzle_actuator.h"
#include "sim/scene_builder.h"
#include "sim/scene_spec.h"

namespace airtwin {

/// Everything fixed about a twin besides the scenario and the field model.
struct TwinParameters {
  SceneParameters scene;
  NozzleActuatorParameters nozzle;
  AirForceParameters air;
  /// The wall jet's transport lag in the CFD's air: each object feels the orientation whose air
  /// has reached it (sim/air_transport.h); front_speed_mps 0 makes the floor pattern swing
  /// rigidly. With cfd_timing and a CFD that has the jet's start-up, the lag and the free jet's
  /// transit (replacing nozzle.field_delay_s) are the CFD's. The analytical air (cfd_air null)
  /// mirrors the controller's model, which takes the new field everywhere at once after the
  /// delay: there the pattern swings rigidly and nozzle.field_delay_s holds, unless
  /// analytical_air_transport is set.
  AirTransportParameters air_transport;
  /// In the analytical air too, each object feels the orientation whose air has reached it by
  /// air_transport (the transport_lag effect; its start-up and formation are the CFD's only).
  bool analytical_air_transport = false;
  /// The air: the jet's CFD (shared, immutable; its tilt range must cover the nozzle's), or null
  /// for the analytical field of the field model the twin is built with.
  std::shared_ptr<const CfdField> cfd_air;
  /// The scene from a user's MJCF file (sim/scene_builder.h load_scene: what it must provide)
  /// instead of built from `scene` and the scenario; empty: built. The other parameters (air,
  /// drag, static friction) still come from here.
  std::string scene_file;
  NozzleOrientation initial_orientation{0.0, 0.0};  ///< servos at rest here at t = 0 (rad)
  bool jet_on_at_start = false;                     ///< jet level 0 at t = 0 either way
  /// Before t = 0 the objects settle this long without air (s): they are dropped 0.2 mm above
  /// the floor and the wads sag ~1-2 mm under their own weight, as placed objects do before a
  /// recording starts. Positions move by < ~1 mm; time() starts at 0 after it.
  double settle_time_s = 0.5;
};

/// An object's planar motion in the twin, world frame: position (m) and velocity (m/s); not to be
/// confused with models' ObjectState (position and eq. 8 speed). For a cotton wad, the
/// area-weighted mean of its bodies' centres of mass and velocities.
struct ObjectMotion {
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();
  Eigen::Vector2d v_W = Eigen::Vector2d::Zero();
};

class Twin {
 public:
  /// Builds the scene. Throws InputError on a bad spec or parameters (naming the object or
  /// field), e.g. a nozzle tilt range reaching past the field model's fold.
  Twin(const SceneSpec& spec, const TwinParameters& params, const AirFieldModel& field_model,
       uint64_t seed);
  ~Twin();
  Twin(Twin&&) noexcept;
  Twin& operator=(Twin&&) noexcept;
  Twin(const Twin&) = delete;
  Twin& operator=(const Twin&) = delete;

  /// One physics step. Throws SimulationError (naming the object and time) when the state goes
  /// non-finite, MuJoCo rejects an acceleration, or the air callback faulted.
  void step();
  /// Steps until time() reaches t_s (to the nearest whole step); no-op if already there.
  void advance_to(double t_s);
  /// advance_to(time() + duration_s).
  void advance(double duration_s);

  /// New nozzle target (rad). Throws InputError outside the servo ranges.
  void command_nozzle(const NozzleOrientation& target);
  /// Jet on/off; settle_jet() jumps the level to its target (a jet running for a long time).
  void set_jet(bool on);
  void settle_jet();

  double time() const;  ///< s, = step_count() * timestep()
  int64_t step_count() const;
  double timestep() const;  ///< s
  NozzleOrientation commanded_orientation() const;
  NozzleOrientation actual_orientation() const;
  NozzleOrientation effective_orientation() const;
  double jet_level() const;  ///< air-speed scale in [0, 1]
  /// The stagnation point of the air the objects are in now (m, world frame).
  Eigen::Vector2d stagnation_point() const;
  /// The analytical field at the effective orientation, not scaled by the jet level: the air the
  /// objects are in unless cfd_air is set (then it is built on this call, as no step reads it; a
  /// twin's accessors are for the thread that steps it).
  const OrientedField& field() const;

  size_t object_count() const;
  const SceneObject& object(size_t i) const;
  ObjectMotion object_state(size_t i) const;
  /// Pushes object i with a horizontal force (N, world frame) at its centre of mass from the next
  /// step on, until pushed again (zero ends it), as a hand or a chute launches an object: each
  /// body takes its share of the mass. Throws InputError unless force_W is finite.
  void push_object(size_t i, const Eigen::Vector2d& force_W);
  std::vector<ObjectMotion> object_states() const;

  /// MuJoCo warnings so far (sum of mjData::warning counts) and the last message seen.
  int warning_count() const;
  const std::string& last_warning() const;

  /// Read access for renderers and tests.
  const mjModel* model() const;
  const mjData* data() const;
  const std::string& scene_xml() const;
  const AirForces& air_forces() const;
  const NozzleActuator& actuator() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace airtwin
