// airtwin aim: the inverse of eqs. (1)-(2), a desired stagnation point -> nozzle (pan, tilt).

#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/cli_common.h"
#include "app/commands.h"
#include "common/errors.h"
#include "common/units.h"
#include "models/field_model_file.h"
#include "models/nozzle_geometry.h"

namespace airtwin::cli {
namespace {

struct AimArgs {
  std::string stagnation;
  double pan_hint_deg = 0.0;
  double max_tilt_deg = 60.0;
  std::string table;
};

void run_aim(const AimArgs& a) {
  const Eigen::Vector2d s = parse_xy(a.stagnation, "--stagnation");
  require_range(a.pan_hint_deg, -360, 360, "--pan-hint", "a pan angle in [-360, 360] deg");
  // eq. (2)'s a1, a2 are the field model's: the one fitted to the CFD unless --table names one.
  NozzleGeometry g = field_model_or_default(a.table).geometry();
  g.tilt_max_rad = deg_to_rad(a.max_tilt_deg);
  require_range(a.max_tilt_deg, 0.001, 89.9, "--max-tilt", "a tilt in (0, 89.9] deg");
  try {
    g.validate();
  } catch (const InputError& e) {
    throw UsageError(std::string("--max-tilt: ") + e.what());
  }
  const AimResult r = aim_at_stagnation(g, s, deg_to_rad(a.pan_hint_deg));
  if (!r.reachable()) {
    throw InputError("--stagnation " + a.stagnation + ": unreachable: " + r.unreachable_reason);
  }
  const NozzleOrientation& o = *r.orientation;
  const Eigen::Vector2d c = projection_point(g, o);
  const Eigen::Vector2d s_back = stagnation_point(g, o);
  nlohmann::ordered_json j;
  j["pan_deg"] = rad_to_deg(o.pan_rad);
  j["tilt_deg"] = rad_to_deg(o.tilt_rad);
  j["projection"] = {c.x(), c.y()};
  j["stagnation"] = {s_back.x(), s_back.y()};
  std::printf("%s\n", j.dump().c_str());
}

}  // namespace

void add_aim_command(CLI::App& app) {
  auto args = std::make_shared<AimArgs>();
  CLI::App* sub = app.add_subcommand(
      "aim",
      "Nozzle orientation that puts the stagnation point at X,Y (inverse of eqs. 1-2).\n"
      "Prints JSON {pan_deg, tilt_deg, projection:[x,y], stagnation:[x,y]}; exit 1 when the\n"
      "point is unreachable.");
  sub->add_option("--stagnation", args->stagnation, "Desired stagnation point 'X,Y' in metres")
      ->required();
  sub->add_option("--pan-hint", args->pan_hint_deg,
                  "Pan (deg) to report when the target is the origin, where any pan works")
      ->capture_default_str();
  sub->add_option("--max-tilt", args->max_tilt_deg, "Largest tilt the nozzle may take, degrees")
      ->capture_default_str();
  sub->add_option("--table", args->table,
                  std::string("Field-model JSON whose eq. (2) a1, a2 place s (a table CSV:\n"
                              "the paper's 0.1, 2.33); ") +
                      kDefaultFieldModelHelp);
  sub->callback([args] { run_aim(*args); });
}

}  // namespace airtwin::cli
