#pragma once
// Helpers shared by the subcommands: flag parsing at the edge (degrees, "X,Y" pairs), output files.

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <initializer_list>
#include <string>
#include <vector>

#include "common/errors.h"
#include "models/trajectory_data.h"
#include "sim/effects.h"
#include "sim/physics_variation.h"

namespace airtwin::cli {

/// Parses "X,Y" (two finite numbers) for flag `flag`; throws UsageError naming the flag.
Eigen::Vector2d parse_xy(const std::string& text, const std::string& flag);

/// Parses "A,B,..." (finite numbers in degrees) for flag `flag` into radians; throws UsageError
/// naming the flag and the bad item, or when the list is empty.
std::vector<double> parse_degree_list(const std::string& text, const std::string& flag);

/// Throws UsageError "<flag>: expected <what>, got <v>" unless v is finite and in [lo, hi].
void require_range(double v, double lo, double hi, const std::string& flag,
                   const std::string& what);

/// Creates the parent directory of `path` if needed; throws InputError when it cannot.
void ensure_parent_dir(const std::string& path);

/// Writes `text` to `path` (creating the parent directory); throws InputError on failure.
void write_text_file(const std::string& path, const std::string& text);

/// The sensor levels of --noise (render, run --vision): none (0, 0), low (3 grey levels of
/// noise, 0.7 px blur), high (6, 1.0). UsageError naming --noise otherwise.
struct NoiseLevel {
  double noise_sigma_grey = 0.0;
  double blur_sigma_px = 0.0;
};
NoiseLevel parse_noise(const std::string& level);

/// --vary-physics's text (run, view, batch, collect): none, documented or a spread in (0, 0.5];
/// UsageError naming the flag and the text otherwise.
PhysicsVariation parse_vary_physics(const std::string& text);

/// One or more trajectory CSVs read as one set (merge_trajectory_sets: with several, each id
/// becomes FILE_INDEX:ID), and how to name them: the path, or "N files, FIRST to LAST".
struct TrajectoryFiles {
  TrajectorySet set;
  std::string source;
};
TrajectoryFiles read_trajectory_files(const std::vector<std::string>& paths);

/// A library field ("collection.per_tilt") and the flag that sets it ("--per-tilt").
struct FlagOf {
  const char* field;
  const char* flag;
};

/// Runs `f`; a FieldError on one of `flags`' fields becomes a UsageError naming the flag (the
/// libraries name their fields, only app/ knows the flags). Other errors pass unchanged.
template <typename F>
decltype(auto) with_flags(std::initializer_list<FlagOf> flags, F&& f) {
  try {
    return f();
  } catch (const FieldError& e) {
    for (const FlagOf& m : flags) {
      if (e.field() == m.field) throw UsageError(std::string(m.flag) + ": " + e.detail());
    }
    throw;
  }
}

/// The flags of collect and calibrate-dynamics that set CollectionOptions' fields.
inline constexpr std::initializer_list<FlagOf> kCollectionFlags = {
    {"collection.object", "--object"},           {"collection.tilts", "--tilts"},
    {"collection.per_tilt", "--per-tilt"},       {"collection.wait_s", "--wait"},
    {"collection.lead_in_s", "--lead-in"},       {"collection.record_s", "--record"},
    {"collection.threads", "--threads"},         {"collection.protocol", "--protocol"},
    {"collection.release_s", "--release-after"}, {"collection.launch_speed", "--launch-speed"},
    {"calibration.iterations", "--iterations"}};

/// The twin's air: the jet's CFD or the controller's analytical field (the default until the
/// controller's model is fitted to the CFD, docs/twin.md).
/// The twin's physics. The defaults are the physical twin (the CFD's air, physical drag with the
/// calibrated parameters: docs/twin.md); --air model --drag eq8 is the mirror of the
/// controller's model.
struct AirFlags {
  std::string air = "cfd";
  std::string cfd_dir = AIRTWIN_CFD_DIR;  ///< the shipped cases (data/cfd/)
  std::string drag = "physical";          ///< the objects' drag law: eq8 | physical
  /// --object-physics TYPE:key=value,... (sim/object_physics.h), applied in order after --drag.
  std::vector<std::string> object_physics;
  /// The wall jet's formation from the CFD's pulses (sim/air_transport.h) is on in CFD air
  /// whose cases have them. --air-formation asks for it (an error when the cases cannot form
  /// the air); --no-air-formation switches it off.
  bool formation = false;
  bool no_formation = false;
  /// --air-formation-time-scale: AirTransportParameters::formation_time_scale.
  double formation_time_scale = AirTransportParameters{}.formation_time_scale;
  /// --air-front-co-flow, --air-front-counter-flow: AirTransportParameters::front_co_flow and
  /// front_counter_flow (the wall jet's front carried by the old air).
  double front_co_flow = AirTransportParameters{}.front_co_flow;
  double front_counter_flow = AirTransportParameters{}.front_counter_flow;
  /// The eddies an object feels swept past it by the air relative to it
  /// (AirForceParameters::turbulence_swept) are on in CFD air. --air-turbulence-swept asks for
  /// them (an error in the model's air); --no-air-turbulence-swept switches them off (T_L alone).
  bool turbulence_swept = false;
  bool no_turbulence_swept = false;
  /// --integrator euler|implicit: MuJoCo's integrator (SceneParameters::implicit_integrator).
  std::string integrator = "euler";
};

/// Adds --air cfd|model, --cfd DIR, --drag eq8|physical, --object-physics, --integrator
/// euler|implicit, --air-formation, --no-air-formation, --air-formation-time-scale,
/// --air-front-co-flow, --air-front-counter-flow, --air-turbulence-swept and
/// --no-air-turbulence-swept to `sub`.
void add_air_flags(CLI::App* sub, AirFlags& flags);

/// UsageError naming --air, --cfd, --drag, --integrator, --air-formation,
/// --no-air-formation, --air-formation-time-scale, --air-front-* or --air-turbulence-swept for a
/// value or a combination
/// none of them takes. Reads no file.
void check_air_flags(const AirFlags& flags);

/// Checks the flags (check_air_flags), then sets twin->cfd_air: the CFD cases of --cfd's folder
/// (read once per folder in a process) for
/// --air cfd, none for --air model; every object type's drag law, then --object-physics.
/// UsageError naming --air, --cfd, --drag or --object-physics; InputError naming the file for
/// unreadable CFD data.
void apply_air_flags(const AirFlags& flags, TwinParameters* twin);

/// What every --table help says of the default field model.
inline constexpr const char* kDefaultFieldModelHelp =
    "default: eqs. (2)-(3) fitted to the jet's CFD,\nmodels/data/cfd_fitted_field_model.json, "
    "built in";

/// What the air flags select, for records: "model", or "cfd" with the folder and a hash of its
/// case headers; then the drag law and any --object-physics.
std::string air_identity(const AirFlags& flags);

/// The effects of the repeatable --effect flag, parsed and applied to `twin` in order; the
/// library's error becomes a UsageError naming --effect.
std::vector<Effect> apply_effect_flags(const std::vector<std::string>& texts, TwinParameters* twin);

}  // namespace airtwin::cli
