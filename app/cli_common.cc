#include "app/cli_common.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>

#include "common/csv.h"
#include "common/errors.h"
#include "common/text.h"
#include "common/units.h"
#include "models/cfd_field.h"
#include "runs/batch_plan.h"
#include "sim/object_physics.h"

namespace airtwin::cli {

Eigen::Vector2d parse_xy(const std::string& text, const std::string& flag) {
  const size_t comma = text.find(',');
  std::optional<double> x, y;
  if (comma != std::string::npos) {
    x = parse_finite_double(text.substr(0, comma));
    y = parse_finite_double(text.substr(comma + 1));
  }
  if (!x || !y) {
    throw UsageError(flag + ": expected two finite numbers 'X,Y' in metres, got '" + text + "'");
  }
  return {*x, *y};
}

void require_range(double v, double lo, double hi, const std::string& flag,
                   const std::string& what) {
  if (!std::isfinite(v) || v < lo || v > hi) {
    throw UsageError(flag + ": expected " + what + ", got " + std::to_string(v));
  }
}

void ensure_parent_dir(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (parent.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(parent, ec);
  if (ec)
    throw InputError(path + ": cannot create directory '" + parent.string() + "': " + ec.message());
}

void write_text_file(const std::string& path, const std::string& text) {
  ensure_parent_dir(path);
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError(path + ": cannot open file for writing");
  out << text;
  out.close();
  if (!out) throw InputError(path + ": write failed");
}

std::vector<double> parse_degree_list(const std::string& text, const std::string& flag) {
  std::vector<double> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    const auto v = parse_finite_double(item);
    if (!v) throw UsageError(flag + ": expected comma-separated degrees, got '" + item + "'");
    out.push_back(deg_to_rad(*v));
  }
  if (out.empty()) throw UsageError(flag + ": give at least one value");
  return out;
}

PhysicsVariation parse_vary_physics(const std::string& text) {
  try {
    return PhysicsVariation::parse(text, "--vary-physics");
  } catch (const FieldError& e) {
    throw UsageError(e.what());
  }
}

NoiseLevel parse_noise(const std::string& level) {
  if (level == "none") return {0.0, 0.0};
  if (level == "low") return {3.0, 0.7};
  if (level == "high") return {6.0, 1.0};
  throw UsageError("--noise: expected none, low or high, got '" + level + "'");
}

std::vector<Effect> apply_effect_flags(const std::vector<std::string>& texts,
                                       TwinParameters* twin) {
  try {
    std::vector<Effect> effects;
    for (const std::string& text : texts) effects.push_back(parse_effect(text));
    apply_effects(effects, twin);
    return effects;
  } catch (const InputError& e) {
    throw UsageError(std::string("--effect: ") + e.what());
  }
}

void add_air_flags(CLI::App* sub, AirFlags& flags) {
  sub->add_option("--air", flags.air,
                  "The air the objects are in: cfd (the jet's CFD, data/cfd/, docs/cfd.md) or\n"
                  "model (the controller's own analytical field, eqs. 1-3: with --drag eq8, a\n"
                  "twin that mirrors the model)")
      ->capture_default_str();
  sub->add_option("--drag", flags.drag,
                  "The objects' drag law: physical (1/2 rho C_D(Re) A |u - v| (u - v), lift and\n"
                  "friction with the types' calibrated parameters; docs/twin.md) or eq8\n"
                  "(c (k u - v), eq. (8) read as physics)")
      ->capture_default_str();
  sub->add_option("--cfd", flags.cfd_dir,
                  "With --air cfd: the folder of CFD cases (default: the shipped data/cfd)");
  sub->add_option("--object-physics", flags.object_physics,
                  "Set an object type's physical parameters, TYPE:key=value,... (repeatable;\n"
                  "TYPE tracer or cotton; docs/twin.md). Keys:\n" +
                      object_physics_help());
  sub->add_option("--integrator", flags.integrator,
                  "MuJoCo's integrator for the built scene: euler (every calibration's) or\n"
                  "implicit (~20 % slower; survives a tracer tumbling at hundreds of rad/s)")
      ->capture_default_str();
  CLI::Option* on = sub->add_flag(
      "--air-formation", flags.formation,
      "In CFD air, each object's air forms at the rate of the CFD's short pulses (a swept jet's\n"
      "air arrives weakened; sim/air_transport.h, docs/twin.md): the default where the cases\n"
      "have the jet's start-up and pulses; given, it is an error when they have not");
  sub->add_flag("--no-air-formation", flags.no_formation,
                "In CFD air, each object gets the reached orientation's whole air at once")
      ->excludes(on);
  sub->add_option("--air-formation-time-scale", flags.formation_time_scale,
                  "The formation's times: the pulses' times this, in (0, 10] (0.5: the 3-D CFD\n"
                  "of a re-aim, docs/cfd.md; other values for measuring how results depend on it)")
      ->capture_default_str();
  sub->add_option("--air-front-co-flow", flags.front_co_flow,
                  "In CFD air, a re-aimed wall jet's front moves at its still-air speed plus this\n"
                  "share of the old air flowing its way, in [0, 2] (1: carried, as the 3-D CFD of\n"
                  "a re-aim shows; 0 with --air-front-counter-flow 0: the lag of still air)")
      ->capture_default_str();
  sub->add_option("--air-front-counter-flow", flags.front_counter_flow,
                  "... less this share of the old air flowing against it, in [0, 2]")
      ->capture_default_str();
  CLI::Option* swept = sub->add_flag(
      "--air-turbulence-swept", flags.turbulence_swept,
      "In CFD air, the eddies each object feels are also swept past it at its speed relative\n"
      "to the mean air, so they decorrelate in 1 / (1 / T_L + |u - v| / L11) rather than T_L\n"
      "(the crossing-trajectories effect; docs/twin.md): the default in CFD air");
  sub->add_flag("--no-air-turbulence-swept", flags.no_turbulence_swept,
                "In CFD air, the eddies decorrelate in the Lagrangian time T_L alone (the\n"
                "controller then plans with the models fitted to that twin,\n"
                "models/data/twin_lagrangian/)")
      ->excludes(swept);
}

void check_air_flags(const AirFlags& flags) {
  SceneParameters scratch;
  with_flags({{"drag", "--drag"}}, [&] { apply_drag_law(flags.drag, &scratch); });
  if (flags.air != "cfd" && flags.air != "model") {
    throw UsageError("--air: expected cfd or model, got '" + flags.air + "'");
  }
  if (flags.air == "model" && flags.cfd_dir != AIRTWIN_CFD_DIR) {
    throw UsageError("--cfd needs --air cfd");
  }
  if (flags.integrator != "euler" && flags.integrator != "implicit") {
    throw UsageError("--integrator: expected euler or implicit, got '" + flags.integrator + "'");
  }
  if (flags.air == "model" && flags.formation) {
    throw UsageError("--air-formation needs --air cfd");
  }
  const bool default_scale =
      flags.formation_time_scale == AirTransportParameters{}.formation_time_scale;
  if (!default_scale && flags.air == "model") {
    throw UsageError("--air-formation-time-scale needs --air cfd");
  }
  if (!default_scale && flags.no_formation) {
    throw UsageError("--air-formation-time-scale needs the formation (drop --no-air-formation)");
  }
  const AirTransportParameters defaults;
  if (flags.air == "model" && (flags.front_co_flow != defaults.front_co_flow ||
                               flags.front_counter_flow != defaults.front_counter_flow)) {
    throw UsageError("--air-front-co-flow and --air-front-counter-flow need --air cfd");
  }
  if (flags.air == "model" && flags.turbulence_swept) {
    throw UsageError("--air-turbulence-swept needs --air cfd");
  }
  AirTransportParameters transport;
  transport.formation_time_scale = flags.formation_time_scale;
  transport.front_co_flow = flags.front_co_flow;
  transport.front_counter_flow = flags.front_counter_flow;
  with_flags({{"air_transport.formation_time_scale", "--air-formation-time-scale"},
              {"air_transport.front_co_flow", "--air-front-co-flow"},
              {"air_transport.front_counter_flow", "--air-front-counter-flow"}},
             [&] { transport.validate(); });
}

void apply_air_flags(const AirFlags& flags, TwinParameters* twin) {
  check_air_flags(flags);
  twin->scene.implicit_integrator = flags.integrator == "implicit";
  apply_drag_law(flags.drag, &twin->scene);
  for (const std::string& text : flags.object_physics) {
    try {
      apply_object_physics(text, &twin->scene);
    } catch (const InputError& e) {
      throw UsageError(std::string("--object-physics: ") + e.what());
    }
  }
  if (flags.air == "model") {
    twin->cfd_air.reset();
    return;
  }
  twin->air.turbulence_swept = !flags.no_turbulence_swept;
  twin->air_transport.formation = !flags.no_formation;
  twin->air_transport.formation_time_scale = flags.formation_time_scale;
  twin->air_transport.front_co_flow = flags.front_co_flow;
  twin->air_transport.front_counter_flow = flags.front_counter_flow;
  // One copy per folder in the process: a batch builds many twins from the same cases.
  static std::mutex mutex;
  static std::map<std::string, std::shared_ptr<const CfdField>> loaded;
  const std::lock_guard<std::mutex> lock(mutex);
  std::shared_ptr<const CfdField>& field = loaded[flags.cfd_dir];
  if (!field) field = std::make_shared<const CfdField>(CfdField::read_dir(flags.cfd_dir));
  if (flags.formation && !field->forms_air()) {
    throw UsageError("--air-formation: " + flags.cfd_dir + " lacks " + CfdField::kFormationData);
  }
  twin->cfd_air = field;
}

std::string air_identity(const AirFlags& flags) {
  std::string drag = ", drag " + flags.drag;
  for (const std::string& text : flags.object_physics) drag += ", " + text;
  if (flags.air == "cfd") {
    drag += flags.no_formation ? ", no air formation"
                               : ", air formation x" + format_number(flags.formation_time_scale);
    drag += ", front carried x" + format_number(flags.front_co_flow) + " / held back x" +
            format_number(flags.front_counter_flow);
    if (flags.no_turbulence_swept) drag += ", turbulence T_L alone";
  }
  if (flags.integrator != "euler") drag += ", integrator " + flags.integrator;
  if (flags.air != "cfd") return flags.air + drag;
  std::vector<std::string> headers;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(flags.cfd_dir, ec)) {
    if (e.path().extension() == ".json") headers.push_back(e.path().string());
  }
  std::sort(headers.begin(), headers.end());
  std::string all;
  for (const std::string& h : headers) {
    std::ifstream in(h, std::ios::binary);
    all += std::string(std::istreambuf_iterator<char>(in), {});
  }
  return "cfd " + flags.cfd_dir + " " + content_hash(all) + drag;
}

TrajectoryFiles read_trajectory_files(const std::vector<std::string>& paths) {
  TrajectoryFiles f;
  std::vector<TrajectorySet> sets;
  for (const std::string& path : paths) sets.push_back(read_trajectory_csv(path));
  f.set = merge_trajectory_sets(std::move(sets));
  f.source = paths.size() == 1 ? paths.front()
                               : std::to_string(paths.size()) + " files, " + paths.front() +
                                     " to " + paths.back();
  return f;
}

}  // namespace airtwin::cli
