#pragma once
// Data collection in the twin, as Appendix D did it on the rig: for each trial, (i) an object is
// placed on the floor with the nozzle idle (pan -90 deg, tilt 50 deg) so that it stays put;
// (ii) the jet is switched on and left 8 s to reach steady state; (iii) the nozzle is turned to
// the trial's orientation and the object is recorded by the top camera for 2 s at 40 Hz. Objects
// are placed 20-58 cm from the trial's stagnation point ("at these distances static pressure
// remains low but air velocity is sufficient to set the objects in motion"), 50 trials per tilt.
//
// The output is the trajectory CSV of the identification (models/trajectory_data.h): one
// trajectory per trial, t = 0 at the re-aim, the command in force (the trial's orientation) on
// every row, positions from the twin's truth (runs/camera_collection.h records the same trials
// through the rendered camera and the detection pipeline, as the rig did).
//
// A second protocol releases the object at rest in air that is already steady: the nozzle rests
// at the trial's orientation with the jet off while the object settles, then the jet is on at its
// steady state from the release (t = 0) on, as when a hand lets go of an object held in a running
// field. Nothing moves the nozzle, so what keeps an object from starting is its friction and the
// air alone: static friction above kinetic acts there, a nozzle's late response cannot (data
// for telling stiction from a late air; at Appendix D's distances they do not separate it from
// a weaker air by themselves, docs/discrepancy.md). `mixed` alternates the two, trial by trial.
//
// Either protocol can release the object from the air part-way through the record (release_s):
// the nozzle turns back to idle, whose air is too weak to move a placed object, and the object
// coasts on its friction and the still air's drag. Appendix D's objects start from rest in the
// jet and slow as it weakens; a coast from speed in still air is what tells the friction of an
// object that has outrun the air (the linearised_drag effect) from eq. (8)'s xi3, which the drag
// inside the jet shares.
//
// A third protocol launches the object across the floor with the nozzle idle throughout: a push
// over the 0.3 s before t = 0 sends it toward the workspace at about a drawn speed (0.5-2.5 m/s by
// default, less the drag on the way), as a chute on a rig would, and it coasts to rest in the idle
// air. No air term acts on it, so its slowing is
// its friction and the still air's drag alone, apart from the air inside the jet that eq. (8)'s
// xi3 also carries; a release (above) tells the same only where the jet's air has decayed.
//
// Determinism: the plan (orientations, starts) and each trial's twin seed come from the seed and
// the trial's index only, so a trial's data do not depend on the thread count or on other trials.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "models/air_field.h"
#include "models/trajectory_data.h"
#include "sim/physics_variation.h"
#include "sim/twin.h"

namespace airtwin {

/// How each trial starts (the catalogue below names them).
enum class CollectionProtocol {
  kReaim,     ///< Appendix D: the nozzle turns from idle to the trial's orientation at t = 0
  kPlaced,    ///< the object is released at t = 0 in the trial's steady air
  kMixed,     ///< even trial indices re-aim, odd ones are placed
  kLaunched,  ///< the object slides off at t = 0 under the idle nozzle and coasts to rest
};

/// The protocol's name as typed: "reaim", "placed", "mixed", "launched".
const char* collection_protocol_name(CollectionProtocol p);
/// The protocol of that name; throws FieldError on "collection.protocol" naming the choices.
CollectionProtocol parse_collection_protocol(const std::string& name);

struct CollectionOptions {
  std::string object = "tracer";                               ///< "tracer" | "cotton"
  std::vector<double> tilts_rad = {0.0, 0.39269908169872414};  ///< 0 and 22.5 deg
  int per_tilt = 50;                                           ///< trials per tilt
  std::uint64_t seed = 1;
  double min_distance_m = 0.20;  ///< start distance from the trial's s
  double max_distance_m = 0.58;
  /// Starts farther than this from the origin are redrawn (the camera sees +-1.35 m).
  double max_start_radius_m = 1.2;
  NozzleOrientation idle{-1.5707963267948966, 0.8726646259971648};  ///< pan -90, tilt 50 deg
  double wait_s = 8.0;    ///< jet on at idle before the re-aim (s)
  double record_s = 2.0;  ///< recording after the re-aim (s)
  /// Recording before the re-aim (s, at most wait_s): frames at t < 0 with the idle command, so
  /// the data show the command change and the nozzle's travel (the discrepancy analysis needs
  /// it to tell a response delay; models/nozzle_response.h). 0: none, as Appendix D.
  double lead_in_s = 0.0;
  /// How the trials start; a lead-in applies to the re-aimed trials only (a placed trial is
  /// recorded from its release).
  CollectionProtocol protocol = CollectionProtocol::kReaim;
  /// Seconds after the re-aim (or the release into steady air) at which the nozzle turns back to
  /// idle and the object coasts (recorded with the idle command from then on); 0: never, as
  /// Appendix D. Below record_s.
  double release_s = 0.0;
  /// Launched trials: the push's target speed (m/s) is uniform in [min, max]. Their direction lies
  /// within 90 deg of the start's way to the origin, so that the coast stays in the camera's view.
  double min_launch_speed_mps = 0.5;
  double max_launch_speed_mps = 2.5;
  double frame_rate_hz = 40.0;
  TwinParameters twin;  ///< the twin's physics (effects applied here)
  /// Active: each trial's object gets its own physics, drawn from the trial's twin seed
  /// (sim/physics_variation.h): a collection over objects that differ, as a rig's several
  /// objects of one type.
  PhysicsVariation physics_variation;
  int threads = 1;  ///< twins run in parallel (0: one per core)

  /// Throws FieldError naming the field ("collection.per_tilt") when a value is out of range.
  void validate() const;
};

/// One trial of the plan.
struct CollectionTrial {
  int index = 0;
  NozzleOrientation target;                           ///< the recorded orientation (rad)
  Eigen::Vector2d start_W = Eigen::Vector2d::Zero();  ///< where the object is placed (m)
  std::uint64_t twin_seed = 0;                        ///< turbulence and shape of this trial
  bool placed = false;  ///< released in steady air instead of re-aimed at (the protocol's choice)
  /// Launched trials: the velocity the push aims at (m/s; zero otherwise); the drag on the way
  /// leaves 0.64-0.85 of it at t = 0.
  /// Their target is the idle orientation, the command of every recorded frame.
  Eigen::Vector2d launch_W = Eigen::Vector2d::Zero();
};

/// The trials: for each tilt in order, per_tilt trials with pan uniform in [-180, 180) deg and the
/// object at a uniform distance in [min, max] from the trial's s in a uniform direction (a
/// launched trial then keeps the start and aims nowhere: its target is the idle).
std::vector<CollectionTrial> plan_collection(const CollectionOptions& options);

/// What a recorder is shown of each recorded frame of a trial: the twin at the frame's time,
/// `frame` its index in the record (0 = the first lead-in frame, or the re-aim without lead-in),
/// t_s its time from the re-aim (s, negative in the lead-in) and the command then in force.
using CollectionFrameRecorder =
    std::function<void(const Twin& twin, int frame, double t_s, const NozzleOrientation& command)>;

/// The objects of the trials of `options`: the trial's object as run_collection_trial builds it,
/// with its own physics under an active variation (else the type's).
SceneSpec collection_trial_scene(const CollectionTrial& trial, const CollectionOptions& options);

/// With an active variation, each trial's object physics: the header "traj" and the catalogue's
/// keys (sim/object_physics.h), then a row per trial of the plan, its trajectory's id and the
/// values in the keys' typed units (the physical law's keys empty under eq. (8)'s); "" otherwise.
std::string collection_objects_csv(const CollectionOptions& options);

/// Runs one trial by the protocol and calls `record` at each of its recorded frames (lead-in,
/// then the re-aim and the record), in time order. A recorder that sees the twin through a camera
/// records what the camera sees (runs/camera_collection.h). Throws SimulationError when the twin
/// fails, and what `record` throws.
void run_collection_trial(const CollectionTrial& trial, const CollectionOptions& options,
                          const AirFieldModel& field, const CollectionFrameRecorder& record);

/// Runs one trial: its recorded trajectory from the twin's truth (id = the trial index). Throws
/// SimulationError when the twin fails.
Trajectory run_collection_trial(const CollectionTrial& trial, const CollectionOptions& options,
                                const AirFieldModel& field);

/// Runs the whole plan (in parallel when options.threads != 1); trajectories in plan order.
/// `progress(done, total)` (optional) is called after each finished trial, from one thread at a
/// time.
TrajectorySet run_collection(const CollectionOptions& options, const AirFieldModel& field,
                             const std::function<void(int, int)>& progress = {});

}  // namespace airtwin
