#include "sim/collection.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <mutex>
#include <thread>

#include "common/errors.h"
#include "common/parallel_for.h"
#include "common/random_stream.h"
#include "common/text.h"
#include "common/units.h"
#include "models/nozzle_geometry.h"

namespace airtwin {

namespace {

struct ProtocolEntry {
  CollectionProtocol id;
  const char* name;
};
// A launch pushes the object this long (s) before t = 0, against its kinetic friction and up to
// the drawn speed less the drag on the way (0.64-0.85 of it), as a chute's slope would: a velocity
// set in one step makes MuJoCo's soft contact jolt (~0.2 m/s lost in the first step at 2 m/s),
// and a push over 0.1 s made the tracer chatter on its contact twice as much as this one.
constexpr double kLaunchPushS = 0.3;

constexpr ProtocolEntry kProtocols[] = {{CollectionProtocol::kReaim, "reaim"},
                                        {CollectionProtocol::kPlaced, "placed"},
                                        {CollectionProtocol::kMixed, "mixed"},
                                        {CollectionProtocol::kLaunched, "launched"}};

}  // namespace

const char* collection_protocol_name(CollectionProtocol p) {
  for (const ProtocolEntry& e : kProtocols) {
    if (e.id == p) return e.name;
  }
  AIRTWIN_DEMAND(false);
  return "";
}

CollectionProtocol parse_collection_protocol(const std::string& name) {
  std::string names;
  for (const ProtocolEntry& e : kProtocols) {
    if (name == e.name) return e.id;
    names += (names.empty() ? "" : ", ") + std::string(e.name);
  }
  throw FieldError("collection.protocol", "expected one of " + names + ", got '" + name + "'");
}

void CollectionOptions::validate() const {
  if (object != "tracer" && object != "cotton") {
    throw FieldError("collection.object", "expected tracer or cotton, got '" + object + "'");
  }
  if (tilts_rad.empty()) throw FieldError("collection.tilts", "give at least one tilt");
  for (double t : tilts_rad) {
    if (!(t >= 0 && t <= twin.nozzle.tilt_max_rad)) {
      throw FieldError("collection.tilts",
                       "each tilt must be in [0, " +
                           std::to_string(rad_to_deg(twin.nozzle.tilt_max_rad)) + "] deg, got " +
                           std::to_string(rad_to_deg(t)));
    }
  }
  if (per_tilt < 1 || per_tilt > 100000) {
    throw FieldError("collection.per_tilt",
                     "expected a count in [1, 100000], got " + std::to_string(per_tilt));
  }
  if (!(min_distance_m > 0 && max_distance_m >= min_distance_m && max_distance_m < 2.0)) {
    throw FieldError("collection.min_distance_m",
                     "start distances: expected 0 < min_distance_m <= max_distance_m < 2 m");
  }
  if (!(wait_s >= 0 && wait_s <= 600)) {
    throw FieldError("collection.wait_s", "expected seconds in [0, 600]");
  }
  if (!(lead_in_s >= 0 && lead_in_s <= wait_s)) {
    throw FieldError("collection.lead_in_s", "expected seconds in [0, wait_s]");
  }
  if (lead_in_s > 0 &&
      (protocol == CollectionProtocol::kPlaced || protocol == CollectionProtocol::kLaunched)) {
    throw FieldError("collection.lead_in_s",
                     std::string(collection_protocol_name(protocol)) +
                         " trials are recorded from their start: a lead-in needs re-aims "
                         "(protocol reaim or mixed)");
  }
  if (!(record_s > 0 && record_s <= 600)) {
    throw FieldError("collection.record_s", "expected seconds in (0, 600]");
  }
  if (!(release_s >= 0 && release_s < record_s)) {
    throw FieldError("collection.release_s", "expected 0 (never) or seconds below the record's " +
                                                 format_number(record_s) + ", got " +
                                                 format_number(release_s));
  }
  if (release_s > 0 && protocol == CollectionProtocol::kLaunched) {
    throw FieldError("collection.release_s",
                     "launched trials run under the idle nozzle throughout: expected 0, got " +
                         format_number(release_s));
  }
  if (!(min_launch_speed_mps > 0 && max_launch_speed_mps >= min_launch_speed_mps &&
        max_launch_speed_mps <= 5.0)) {
    throw FieldError("collection.launch_speed", "expected speeds 0 < min <= max <= 5 m/s, got " +
                                                    format_number(min_launch_speed_mps) + ", " +
                                                    format_number(max_launch_speed_mps));
  }
  if (!(frame_rate_hz >= 1 && frame_rate_hz <= 1000)) {
    throw FieldError("collection.frame_rate_hz", "expected a rate in [1, 1000] Hz");
  }
  if (threads < 0 || threads > 256) {
    throw FieldError("collection.threads", "expected a count in [0, 256]");
  }
}

std::vector<CollectionTrial> plan_collection(const CollectionOptions& o) {
  o.validate();
  const NozzleGeometry geometry;
  std::vector<CollectionTrial> plan;
  for (double tilt : o.tilts_rad) {
    for (int k = 0; k < o.per_tilt; ++k) {
      CollectionTrial trial;
      trial.index = static_cast<int>(plan.size());
      RandomStream rs(o.seed, RandomPurpose::kCollection, static_cast<uint64_t>(trial.index));
      // Redraw until the start lies in the camera's view (a few draws at most for tilts <= 45).
      for (int attempt = 0;; ++attempt) {
        trial.target = {rs.uniform(-kPi, kPi), tilt};
        const Eigen::Vector2d s = stagnation_point(geometry, trial.target);
        const double a = rs.uniform(-kPi, kPi);
        const double r = rs.uniform(o.min_distance_m, o.max_distance_m);
        trial.start_W = s + r * Eigen::Vector2d(std::cos(a), std::sin(a));
        if (trial.start_W.norm() <= o.max_start_radius_m) break;
        if (attempt == 1000) {
          throw FieldError("collection.tilts",
                           "no start position within " + std::to_string(o.max_start_radius_m) +
                               " m of the origin at tilt " + std::to_string(rad_to_deg(tilt)) +
                               " deg: the tilt is too large for the camera's view");
        }
      }
      trial.twin_seed = static_cast<uint64_t>(rs.uniform() * 0x1.0p53);
      trial.placed = o.protocol == CollectionProtocol::kPlaced ||
                     (o.protocol == CollectionProtocol::kMixed && trial.index % 2 == 1);
      if (o.protocol == CollectionProtocol::kLaunched) {
        // Drawn after every other protocol's numbers, which therefore keep their plans.
        const double speed = rs.uniform(o.min_launch_speed_mps, o.max_launch_speed_mps);
        const double toward_origin = std::atan2(-trial.start_W.y(), -trial.start_W.x());
        const double heading = toward_origin + rs.uniform(-0.5 * kPi, 0.5 * kPi);
        trial.launch_W = speed * Eigen::Vector2d(std::cos(heading), std::sin(heading));
        trial.target = o.idle;
      }
      plan.push_back(trial);
    }
  }
  return plan;
}

SceneSpec collection_trial_scene(const CollectionTrial& trial, const CollectionOptions& o) {
  SceneSpec spec;
  spec.source = "collection trial " + std::to_string(trial.index);
  spec.objects.push_back({std::to_string(trial.index), o.object, trial.start_W, std::nullopt});
  vary_object_physics(o.physics_variation, o.twin.scene, trial.twin_seed, &spec);
  return spec;
}

std::string collection_objects_csv(const CollectionOptions& o) {
  if (!o.physics_variation.active()) return "";
  std::string csv = "traj";
  for (const ObjectPhysicsSpec& key : object_physics_catalogue()) {
    csv += ',';
    csv += key.key;
  }
  csv += "\n";
  for (const CollectionTrial& trial : plan_collection(o)) {
    const SceneSpec scene = collection_trial_scene(trial, o);
    const ObjectSpec& object = scene.objects.front();
    csv += object.id;
    for (const ObjectPhysicsSpec& key : object_physics_catalogue()) {
      csv += ',';
      // The keys of the physical law are empty cells under eq. (8)'s.
      if (!key.physical_law_only || object.physics->drag_law == DragLaw::kPhysical) {
        csv += format_number(object_physics_value(*object.physics, key.id));
      }
    }
    csv += "\n";
  }
  return csv;
}

void run_collection_trial(const CollectionTrial& trial, const CollectionOptions& o,
                          const AirFieldModel& field, const CollectionFrameRecorder& record) {
  const SceneSpec spec = collection_trial_scene(trial, o);
  TwinParameters params = o.twin;
  params.initial_orientation = trial.placed ? trial.target : o.idle;  // (i) placed, jet off
  params.jet_on_at_start = false;
  Twin twin(spec, params, field, trial.twin_seed);
  const int frames = static_cast<int>(std::floor(o.record_s * o.frame_rate_hz + 1e-9));

  // The record from t0 on: the trial's command, and with a release the idle from release_s on.
  const auto record_from = [&](double t0, int first_frame) {
    bool released = false;
    for (int k = 0; k <= frames; ++k) {
      const double t = k / o.frame_rate_hz;
      if (o.release_s > 0.0 && !released && t >= o.release_s) {
        twin.advance_to(t0 + o.release_s);
        twin.command_nozzle(o.idle);
        released = true;
      }
      twin.advance_to(t0 + t);
      record(twin, first_frame + k, t, released ? o.idle : trial.target);
    }
  };

  if (o.protocol == CollectionProtocol::kLaunched) {
    // The jet at idle over the resting object as in Appendix D's wait, then the launch.
    twin.set_jet(true);
    twin.advance(std::max(0.0, o.wait_s - kLaunchPushS));
    const SceneObject& object = twin.object(0);
    const double friction_mps2 =
        physics_of(object, o.twin.scene).kinetic_friction * -o.twin.scene.gravity_W().z();
    const Eigen::Vector2d along = trial.launch_W.normalized();
    twin.push_object(0, object.mass_kg * (trial.launch_W / kLaunchPushS + friction_mps2 * along));
    twin.advance(kLaunchPushS);
    twin.push_object(0, Eigen::Vector2d::Zero());
    record_from(twin.time(), 0);
    return;
  }
  if (trial.placed) {
    // Settled with the jet off under the still nozzle, then released into its steady air.
    twin.advance(o.wait_s);
    const double t0 = twin.time();
    twin.set_jet(true);
    twin.settle_jet();
    record_from(t0, 0);
    return;
  }

  twin.set_jet(true);  // (ii) jet on, wait for the steady state
  const int lead_frames = static_cast<int>(std::floor(o.lead_in_s * o.frame_rate_hz + 1e-9));
  const double lead_s = lead_frames / o.frame_rate_hz;
  twin.advance(o.wait_s - lead_s);
  const double t0 = twin.time() + lead_s;  // the re-aim

  int frame = 0;
  for (int k = -lead_frames; k < 0; ++k) {  // the lead-in, at the idle command
    const double t = k / o.frame_rate_hz;
    twin.advance_to(t0 + t);
    record(twin, frame++, t, o.idle);
  }
  twin.advance_to(t0);
  twin.command_nozzle(trial.target);  // (iii) re-aim and record
  record_from(t0, frame);
}

Trajectory run_collection_trial(const CollectionTrial& trial, const CollectionOptions& o,
                                const AirFieldModel& field) {
  Trajectory tr;
  tr.id = std::to_string(trial.index);
  tr.object = o.object;
  run_collection_trial(trial, o, field,
                       [&](const Twin& twin, int, double t, const NozzleOrientation& command) {
                         tr.samples.push_back({t, twin.object_state(0).p_W, command});
                       });
  return tr;
}

TrajectorySet run_collection(const CollectionOptions& o, const AirFieldModel& field,
                             const std::function<void(int, int)>& progress) {
  const std::vector<CollectionTrial> plan = plan_collection(o);
  const int n = static_cast<int>(plan.size());
  TrajectorySet set;
  set.trajectories.resize(plan.size());

  const int threads =
      o.threads == 0 ? static_cast<int>(std::thread::hardware_concurrency()) : o.threads;
  std::mutex mutex;  // guards done and the progress callback
  int done = 0;
  parallel_for(plan.size(), threads, [&](size_t i) {
    Trajectory tr = run_collection_trial(plan[i], o, field);
    const std::lock_guard lock(mutex);
    set.trajectories[i] = std::move(tr);
    ++done;
    if (progress) progress(done, n);
  });
  return set;
}

}  // namespace airtwin
