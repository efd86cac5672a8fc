// airtwin calibrate-dynamics: tunes the twin's drag and friction for one object type until
// `identify` on `collect`ed data returns the target coefficients (sim/dynamics_calibration.h).
// Prints each round and writes a JSON record; docs/twin.md keeps the shipped numbers.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "app/cli_common.h"
#include "app/commands.h"
#include "common/csv.h"
#include "common/errors.h"
#include "common/text.h"
#include "common/units.h"
#include "models/field_model_file.h"
#include "sim/drag_calibration.h"
#include "sim/dynamics_calibration.h"

namespace airtwin::cli {
namespace {

struct CalibrateArgs {
  std::string tilts = "0,22.5";
  std::string target;  // "xi1,xi2,xi3"; default: the paper's for the object
  std::string out;
  std::string table;                // the controller's field model identification uses
  std::vector<std::string> search;  // --search KEY=MIN:MAX:N (physical drag)
  int refinements = 1;
  int held_out_seeds = 0;            // --held-out-seeds N: the best point checked on N seeds
  std::uint64_t held_out_first = 0;  // from this seed (0: the calibration's seed + 1)
  AirFlags air;
  DynamicsCalibrationOptions options;
};

nlohmann::ordered_json triple(const ObjectDynamics& d) {
  return {{"xi1", d.xi1}, {"xi2", d.xi2}, {"xi3", d.xi3}};
}

// The windows searched by default (docs/twin.md, "Calibrating it"): C_D from a
// hemisphere's 0.34 in free stream to a bluff body's ~1.2 in the floor's shear layer, kinetic
// friction of foam or fibre on a smooth hard floor, the static excess of such pairs.
std::vector<DragCalibrationAxis> default_axes() {
  return {{ObjectPhysicsKey::kDragCoefficient, 0.3, 1.2, 4},
          {ObjectPhysicsKey::kKineticFriction, 0.2, 0.6, 5},
          {ObjectPhysicsKey::kStaticRatio, 1.0, 1.4, 2}};
}

// "KEY=MIN:MAX:N" or "KEY=VALUE" (fixed).
DragCalibrationAxis parse_axis(const std::string& text) {
  const std::string bad =
      "--search: expected KEY=MIN:MAX:N or KEY=VALUE with KEY one of the object-physics keys, "
      "got '" +
      text + "'";
  const size_t eq = text.find('=');
  if (eq == std::string::npos) throw UsageError(bad);
  const std::string key = text.substr(0, eq);
  DragCalibrationAxis a;
  bool found = false;
  for (const ObjectPhysicsSpec& s : object_physics_catalogue()) {
    if (key == s.key) {
      a.key = s.id;
      found = true;
    }
  }
  if (!found) throw UsageError(bad);
  std::vector<std::string> parts;
  std::stringstream ss(text.substr(eq + 1));
  for (std::string item; std::getline(ss, item, ':');) parts.push_back(item);
  if (parts.size() == 1) {
    const auto v = parse_finite_double(parts[0]);
    if (!v) throw UsageError(bad);
    a.min = a.max = *v;
    a.points = 1;
    return a;
  }
  if (parts.size() != 3) throw UsageError(bad);
  const auto lo = parse_finite_double(parts[0]), hi = parse_finite_double(parts[1]);
  const auto n = parse_finite_double(parts[2]);
  if (!lo || !hi || !n || *n != std::floor(*n)) throw UsageError(bad);
  a.min = *lo;
  a.max = *hi;
  a.points = static_cast<int>(*n);
  return a;
}

// Median and range of a figure, or null when no check had it.
nlohmann::ordered_json spread(const DragCheckSpread& s) {
  if (s.n == 0) return nullptr;
  return {{"median", s.median}, {"min", s.min}, {"max", s.max}};
}

// The record of the held-out checks: each collection's figures, and their summary.
template <class PointJson>
nlohmann::ordered_json held_out_json(const std::vector<DragCalibrationCheck>& checks,
                                     const PointJson& point_json) {
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (const DragCalibrationCheck& k : checks) {
    nlohmann::ordered_json r = {{"seed", k.seed}};
    r.update(point_json(k.point));
    r.erase("values");
    r["repeatability_pct"] = std::isfinite(k.repeatability_pct)
                                 ? nlohmann::ordered_json(k.repeatability_pct)
                                 : nlohmann::ordered_json(nullptr);
    r["air_term_kept"] = k.air_term_kept();
    rows.push_back(r);
  }
  const DragCheckSummary sum = summarize_checks(checks);
  nlohmann::ordered_json by_tilt = nlohmann::ordered_json::object();
  for (const auto& [tilt, v] : sum.mape_by_tilt_pct) by_tilt[format_number(tilt)] = spread(v);
  nlohmann::ordered_json by_sector = nlohmann::ordered_json::object();
  for (const auto& [tilt, sectors] : sum.mape_by_tilt_sector_pct) {
    nlohmann::ordered_json per = nlohmann::ordered_json::object();
    for (const PlacementSectorInfo& info : kPlacementSectorCatalogue) {
      per[info.name] = spread(sectors[static_cast<size_t>(info.sector)]);
    }
    by_sector[format_number(tilt)] = per;
  }
  return {{"seeds", rows.size()},
          {"summary",
           {{"air_term_lost", sum.air_term_lost},
            {"worst_relative_error", spread(sum.worst_relative_error)},
            {"end_position_mape_by_tilt", by_tilt},
            {"end_position_mape_by_sector", by_sector},
            {"repeatability_pct", spread(sum.repeatability_pct)},
            {"full_library_is_eq8", sum.full_library_is_eq8}}},
          {"checks", rows}};
}

// The summary for people: "median [min-max]" of each figure.
std::string held_out_text(const nlohmann::ordered_json& summary, size_t seeds) {
  const auto range = [](const nlohmann::ordered_json& s, double scale) {
    if (s.is_null()) return std::string("-");
    char t[64];
    std::snprintf(t, sizeof t, "%.1f [%.1f-%.1f]", scale * s["median"].get<double>(),
                  scale * s["min"].get<double>(), scale * s["max"].get<double>());
    return std::string(t);
  };
  std::string mapes;
  for (const auto& [tilt, s] : summary["end_position_mape_by_tilt"].items()) {
    mapes += (mapes.empty() ? "" : ", ") + tilt + " deg " + range(s, 1.0) + " %";
  }
  // Where around s (models/trajectory_replay.h): each sector's spread over the collections.
  for (const auto& [tilt, sectors] : summary["end_position_mape_by_sector"].items()) {
    mapes += "\n    " + tilt + " deg by placement from s:";
    const char* sep = " ";
    for (const auto& [name, s] : sectors.items()) {
      mapes += sep + name + " " + range(s, 1.0) + " %";
      sep = ", ";
    }
  }
  const int lost = summary["air_term_lost"].get<int>();
  return "held out, " + std::to_string(seeds) + " collections: the air term lost in " +
         std::to_string(lost) + "\n  of the " + std::to_string(seeds - static_cast<size_t>(lost)) +
         " that keep it: worst coefficient error " + range(summary["worst_relative_error"], 100.0) +
         " %\n  end MAPE " + (mapes.empty() ? std::string("-") : mapes) + "\n  repeatability " +
         range(summary["repeatability_pct"], 1.0) +
         " % (paper 7.7 %)\n  the full library exactly 1, v, vair in " +
         std::to_string(summary["full_library_is_eq8"].get<int>()) + "\n";
}

void run_calibrate_physical(CalibrateArgs a) {
  DragCalibrationOptions o;
  o.collection = a.options.collection;
  o.identification = a.options.identification;
  o.target = a.options.target;
  o.refinements = a.refinements;
  if (a.search.empty()) {
    o.axes = default_axes();
  } else {
    for (const std::string& t : a.search) o.axes.push_back(parse_axis(t));
  }
  with_flags({{"calibration.object", "--object"},
              {"calibration.axes", "--search"},
              {"calibration.refinements", "--refinements"},
              {"calibration target", "--target"}},
             [&] { o.validate(); });
  const AirFieldModel field = field_model_or_default(a.table);
  std::vector<std::string> keys;
  for (const DragCalibrationAxis& ax : o.axes) {
    keys.push_back(object_physics_catalogue()[static_cast<size_t>(ax.key)].key);
  }
  const auto row = [&](const DragCalibrationPoint& p) {
    std::string values;
    for (size_t i = 0; i < keys.size(); ++i) {
      values += (i ? "," : "") + keys[i] + "=" + format_number(p.values[i]);
    }
    char line[512];
    std::snprintf(line, sizeof line,
                  "%-40s (%7.3f, %6.3f, %7.3f)  worst %5.1f%%  R^2 %.3f  MAPE %5.1f%%  full "
                  "library: %s",
                  values.c_str(), p.eq8_form.xi1, p.eq8_form.xi2, p.eq8_form.xi3,
                  100 * p.worst_relative_error, p.r2, p.end_position_mape_pct,
                  p.full_library_terms.c_str());
    return std::string(line);
  };
  const auto progress = [&](const DragCalibrationPoint& p, size_t i) {
    std::fprintf(stderr, "calibrate-dynamics: point %zu: %s\n", i + 1, row(p).c_str());
  };
  std::vector<std::uint64_t> held_out;
  if (a.held_out_seeds != 0) {
    require_range(a.held_out_seeds, 1, 1000, "--held-out-seeds", "a count in [1, 1000]");
    const std::uint64_t first = a.held_out_first != 0 ? a.held_out_first : o.collection.seed + 1;
    for (int k = 0; k < a.held_out_seeds; ++k) held_out.push_back(first + k);
    // Checked before the search: a seed list the check would refuse wastes no grid.
    if (std::find(held_out.begin(), held_out.end(), o.collection.seed) != held_out.end()) {
      throw UsageError("--held-out-seeds: seeds " + std::to_string(first) + "-" +
                       std::to_string(held_out.back()) + " hold the calibration's --seed " +
                       std::to_string(o.collection.seed) + "; start them elsewhere with " +
                       "--held-out-first-seed");
    }
  } else if (a.held_out_first != 0) {
    throw UsageError("--held-out-first-seed needs --held-out-seeds N");
  }
  const DragCalibration c = calibrate_drag(o, field, progress);

  const auto point_json = [&](const DragCalibrationPoint& p) {
    nlohmann::ordered_json values = nlohmann::ordered_json::object();
    for (size_t i = 0; i < keys.size(); ++i) values[keys[i]] = p.values[i];
    nlohmann::ordered_json by_tilt = nlohmann::ordered_json::object();
    for (const auto& [tilt, mape] : p.mape_by_tilt_pct) by_tilt[format_number(tilt)] = mape;
    return nlohmann::ordered_json{{"values", values},
                                  {"identified_eq8_form", triple(p.eq8_form)},
                                  {"r2", p.r2},
                                  {"end_position_mape", p.end_position_mape_pct},
                                  {"end_position_mape_by_tilt", by_tilt},
                                  {"worst_relative_error", p.worst_relative_error},
                                  {"full_library_terms", p.full_library_terms}};
  };
  nlohmann::ordered_json points = nlohmann::ordered_json::array();
  for (const DragCalibrationPoint& p : c.points) points.push_back(point_json(p));
  const DragCalibrationPoint& best = c.points[c.best];
  std::string physics = o.collection.object + ":";
  for (size_t i = 0; i < keys.size(); ++i) {
    physics += (i ? "," : "") + keys[i] + "=" + format_number(best.values[i]);
  }
  const nlohmann::ordered_json j = {
      {"object", o.collection.object},
      {"air", air_identity(a.air)},
      {"drag", "physical"},
      {"table", a.table.empty() ? "built-in" : a.table},
      {"target", triple(o.target)},
      {"best", c.best},
      {"best_object_physics", physics},
      {"best_repeatability_pct", std::isfinite(c.best_repeatability_pct)
                                     ? nlohmann::ordered_json(c.best_repeatability_pct)
                                     : nlohmann::ordered_json(nullptr)},
      {"per_tilt", o.collection.per_tilt},
      {"seed", o.collection.seed},
      {"points", points}};
  std::printf(
      "best of %zu points: %s\n  repeatability %.1f %% (paper 7.7 %%)\n  --object-physics %s\n",
      c.points.size(), row(best).c_str(), c.best_repeatability_pct, physics.c_str());
  nlohmann::ordered_json record = j;
  if (!held_out.empty()) {
    const auto checked = [&](const DragCalibrationCheck& k, size_t i) {
      std::fprintf(stderr,
                   "calibrate-dynamics: held out %zu/%zu, seed %llu: %s  repeatability %.1f%%\n",
                   i + 1, held_out.size(), static_cast<unsigned long long>(k.seed),
                   row(k.point).c_str(), k.repeatability_pct);
    };
    const std::vector<DragCalibrationCheck> checks =
        check_drag_point(o, best.values, held_out, field, checked);
    record["held_out"] = held_out_json(checks, point_json);
    std::printf("%s", held_out_text(record["held_out"]["summary"], checks.size()).c_str());
  }
  write_text_file(a.out, record.dump(2) + "\n");
  std::printf("written to %s\n", a.out.c_str());
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
  if (a.air.drag == "physical") {
    run_calibrate_physical(a);
    return;
  }
  if (!a.search.empty() || !a.table.empty() || a.held_out_seeds != 0) {
    throw UsageError(std::string(!a.search.empty()       ? "--search"
                                 : a.held_out_seeds != 0 ? "--held-out-seeds"
                                                         : "--table") +
                     " needs --drag physical");
  }

  const AirFieldModel field = AirFieldModel::with_constructed_table();
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
      "With --drag physical: a grid search of the type's physical parameters (--search) for\n"
      "the point whose identification comes closest to the target. Prints each round or\n"
      "point and writes a JSON record. docs/twin.md.");
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
  sub->add_option("--search", args->search,
                  "With --drag physical: a searched parameter, KEY=MIN:MAX:N (N grid points) or\n"
                  "KEY=VALUE (held), KEY an --object-physics key (repeatable; default\n"
                  "cd=0.3:1.2:4, mu_k=0.2:0.6:5, mu_s_ratio=1:1.4:2)");
  sub->add_option("--refinements", args->refinements,
                  "With --drag physical: grids around the best point, each at half the spacing")
      ->capture_default_str();
  sub->add_option("--held-out-seeds", args->held_out_seeds,
                  "With --drag physical: check the best point on N collections the search did\n"
                  "not see (the whole protocol at each seed) and report each figure's median and\n"
                  "range, and how often the air term is lost");
  sub->add_option("--held-out-first-seed", args->held_out_first,
                  "The first of them (default: --seed + 1)");
  sub->add_option("--table", args->table,
                  std::string("With --drag physical: the controller's field model identification\n"
                              "uses (coefficient table CSV or field-model JSON); ") +
                      kDefaultFieldModelHelp);
  sub->add_option("--out", args->out, "Output JSON record")->required();
  sub->callback([args] { run_calibrate(*args); });
}

}  // namespace airtwin::cli
