// airtwin calibrate-dynamics: tunes the twin's drag and friction for one object type until
// `identify` on `collect`ed data returns the target coefficients (sim/dynamics_calibration.h).
// Prints each round and writes a JSON record; docs/twin.md keeps the shipped numbers.

#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "app/cli_common.h"
#include "app/commands.h"
#include "common/csv.h"
#include "common/errors.h"
#include "common/units.h"
#include "sim/dynamics_calibration.h"

namespace airtwin::cli {
namespace {

struct CalibrateArgs {
  std::string tilts = "0,22.5";
  std::string target;  // "xi1,xi2,xi3"; default: the paper's for the object
  std::string out;
  AirFlags air;
  DynamicsCalibrationOptions options;
};

nlohmann::ordered_json triple(const ObjectDynamics& d) {
  return {{"xi1", d.xi1}, {"xi2", d.xi2}, {"xi3", d.xi3}};
}

void run_calibrate(CalibrateArgs a) {
  DynamicsCalibrationOptions& o = a.options;
  o.collection.tilts_rad = parse_degree_list(a.tilts, "--tilts");
  with_flags(kCollectionFlags, [&] { o.collection.validate(); });
  o.target = o.collection.object == "tracer" ? kTracerDynamics : kCottonDynamics;
  if (!a.target.empty()) {
    std::stringstream ts(a.target);
    double x[3];
    int n = 0;
    for (std::string item; std::getline(ts, item, ',') && n < 4; ++n) {
      const auto v = parse_finite_double(item);
      if (!v || n >= 3) throw UsageError("--target: expected xi1,xi2,xi3, got '" + a.target + "'");
      x[n] = *v;
    }
    if (n != 3) throw UsageError("--target: expected xi1,xi2,xi3, got '" + a.target + "'");
    o.target = {x[0], x[1], x[2]};
    try {
      o.target.validate("--target");
    } catch (const InputError& e) {
      throw UsageError(e.what());
    }
  }
  require_range(o.iterations, 1, 20, "--iterations", "a count in [1, 20]");
  apply_air_flags(a.air, &o.collection.twin);
  ensure_parent_dir(a.out);

  const AirFieldModel field = AirFieldModel::with_default_table();
  const auto progress = [&](const DynamicsCalibrationStep& s, int round, int rounds) {
    std::fprintf(stderr,
                 "calibrate-dynamics: round %d/%d: physics (%.3f, %.3f, %.3f) -> identified "
                 "(%.3f, %.3f, %.3f), R^2 %.3f, MAPE %.1f%%\n",
                 round, rounds, s.physics.xi1, s.physics.xi2, s.physics.xi3, s.identified.xi1,
                 s.identified.xi2, s.identified.xi3, s.r2, s.end_position_mape_pct);
  };
  const DynamicsCalibration c =
      with_flags(kCollectionFlags, [&] { return calibrate_dynamics(o, field, progress); });

  nlohmann::ordered_json rounds = nlohmann::ordered_json::array();
  std::printf(
      "round  physics (x1, x2, x3)            identified (xi1, xi2, xi3)      R^2    "
      "MAPE   worst\n");
  for (size_t i = 0; i < c.history.size(); ++i) {
    const DynamicsCalibrationStep& s = c.history[i];
    std::printf("%5zu  (%7.3f, %6.3f, %7.3f)   (%7.3f, %6.3f, %7.3f)   %.3f  %5.1f%%  %5.1f%%\n",
                i + 1, s.physics.xi1, s.physics.xi2, s.physics.xi3, s.identified.xi1,
                s.identified.xi2, s.identified.xi3, s.r2, s.end_position_mape_pct,
                100 * s.worst_relative_error);
    nlohmann::ordered_json by_tilt = nlohmann::ordered_json::object();
    for (const auto& [tilt, mape] : s.mape_by_tilt_pct) {
      char key[32];
      std::snprintf(key, sizeof key, "%g", tilt);
      by_tilt[key] = mape;
    }
    rounds.push_back({{"physics", triple(s.physics)},
                      {"identified", triple(s.identified)},
                      {"r2", s.r2},
                      {"end_position_mape", s.end_position_mape_pct},
                      {"end_position_mape_by_tilt", by_tilt},
                      {"worst_relative_error", s.worst_relative_error}});
  }
  if (!c.stopped.empty()) std::printf("stopped early: %s\n", c.stopped.c_str());
  const ObjectTypeParameters p = ObjectTypeParameters::from_dynamics(c.physics, 1.0, 1.0);
  const nlohmann::ordered_json j = {
      {"object", o.collection.object},
      {"air", a.air.air},
      {"target", triple(o.target)},
      {"physics", triple(c.physics)},
      {"drag_rate_per_s", p.drag_rate_per_s},
      {"air_gain", p.air_gain},
      {"kinetic_friction", p.kinetic_friction},
      {"per_tilt", o.collection.per_tilt},
      {"skip_transient_s", o.identification.pairs.transient_s},
      {"seed", o.collection.seed},
      {"rounds", rounds},
      {"stopped",
       c.stopped.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(c.stopped)}};
  write_text_file(a.out, j.dump(2) + "\n");
  std::printf(
      "best physics (%.4f, %.4f, %.4f): drag rate %.4f 1/s, air gain %.4f, mu_k %.4f; "
      "written to %s\n",
      c.physics.xi1, c.physics.xi2, c.physics.xi3, p.drag_rate_per_s, p.air_gain,
      p.kinetic_friction, a.out.c_str());
}

}  // namespace

void add_calibrate_dynamics_command(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* sub = app.add_subcommand(
      "calibrate-dynamics",
      "Tune the twin's drag rate, air gain and kinetic friction for one object type until\n"
      "'identify' on 'collect'ed data (Appendix D protocol) returns the target eq. (8)\n"
      "coefficients (default: the paper's). Fixed-point iteration, one collection per round.\n"
      "Prints the rounds and writes a JSON record. docs/twin.md.");
  DynamicsCalibrationOptions& o = args->options;
  sub->add_option("--object", o.collection.object, "tracer | cotton")->capture_default_str();
  sub->add_option("--target", args->target, "xi1,xi2,xi3 to reach (default: the paper's)");
  sub->add_option("--tilts", args->tilts, "Comma-separated tilts (deg)")->capture_default_str();
  sub->add_option("--per-tilt", o.collection.per_tilt, "Trials per tilt and round")
      ->capture_default_str();
  sub->add_option("--iterations", o.iterations, "Rounds")->capture_default_str();
  sub->add_option("--seed", o.collection.seed, "Seed of every round's collection")
      ->capture_default_str();
  o.collection.threads =
      0;  // every core by default: the result does not depend on the thread count
  sub->add_option("--threads", o.collection.threads, "Twins in parallel (0: one per core)")
      ->capture_default_str();
  sub->add_option("--skip-transient", o.identification.pairs.transient_s,
                  "Identification: seconds after the re-aim not used (see 'identify --help')")
      ->capture_default_str();
  add_air_flags(sub, args->air);
  sub->add_option("--out", args->out, "Output JSON record")->required();
  sub->callback([args] { run_calibrate(*args); });
}

}  // namespace airtwin::cli
