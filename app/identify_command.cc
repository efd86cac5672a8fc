// airtwin identify: section IV. Measured trajectories (or a speed series) in, the identified
// object model out as model.json (models/identification.h, docs/identification.md); a short
// human summary on stdout.

#include <cmath>
#include <cstdio>
#include <memory>
#include <set>
#include <string>

#include "app/cli_common.h"
#include "app/commands.h"
#include "common/errors.h"
#include "common/units.h"
#include "models/field_model_file.h"
#include "models/identification.h"

namespace airtwin::cli {
namespace {

struct IdentifyArgs {
  std::vector<std::string> data;
  std::string series;
  std::string table;
  std::string object;
  std::string method = "robust-esindy";
  std::string out;
  bool no_glitch_repair = false;
  double max_direction_error_deg = 30.0;
  std::string terms;
  IdentificationOptions options;
};

void print_summary(const IdentifiedModel& m, const std::string& out) {
  std::printf("identified %s (%s, %zu pairs from %zu samples, %zu dropped as stationary",
              m.object.empty() ? "series" : m.object.c_str(), m.method.c_str(), m.n_pairs,
              m.n_samples, m.n_dropped);
  if (m.n_glitches_repaired) std::printf(", %zu glitched frames repaired", m.n_glitches_repaired);
  if (m.n_off_radial) std::printf(", %zu not radial from s", m.n_off_radial);
  if (m.n_transient) std::printf(", %zu in transients", m.n_transient);
  if (m.speed_noise_mps > 0.0) {
    std::printf(", v noise %.3g m/s, %zu negative v", m.speed_noise_mps, m.n_negative_speeds);
  }
  std::printf(")\n  dv/dt =");
  bool first = true;
  for (int j = 0; j < kSindyTerms; ++j) {
    if (m.coefficients[j] == 0.0) continue;
    const double c = m.coefficients[j];
    if (first)
      std::printf(" %.4g", c);
    else
      std::printf(" %s %.4g", c < 0 ? "-" : "+", std::abs(c));
    if (j > 0) std::printf(" %s", kTermNames[j]);
    first = false;
  }
  if (first) std::printf(" 0");
  // Every term with a factor v: dv/dt = 0 at v = 0, the model never sets a resting object in
  // motion, though Appendix D releases every object from rest.
  bool starts_from_rest = false;
  for (int j = 0; j < kSindyTerms; ++j) {
    const std::string name = kTermNames[j];
    if (m.coefficients[j] != 0.0 && (name == "1" || name.rfind("vair", 0) == 0)) {
      starts_from_rest = true;
    }
  }
  if (!first && !starts_from_rest) {
    std::printf(
        "\n  note: every term has a factor v, so this model cannot set an object at rest in motion;"
        "\n  if the structure is known, --terms 1,v,vair fits eq. (8)'s (docs/identification.md)");
  }
  std::printf("\n  R^2 = %.3f (of v_{k+1}; of the one-step change: %.3f)", m.r2, m.r2_change);
  if (m.end_position_mape_pct) {
    std::printf(", end-position MAPE = %.1f%% over %zu trajectories", *m.end_position_mape_pct,
                m.n_mape_trajectories);
    for (const auto& [tilt, mape] : m.end_position_mape_by_tilt_pct)
      std::printf("; %g deg: %.1f%%", tilt, mape);
    // Where around s the model errs (models/trajectory_replay.h): n, MAPE and how many it
    // predicted to stay at rest, per sector.
    for (const auto& [tilt, sectors] : m.end_position_by_sector) {
      std::printf("\n    %g deg by placement from s:", tilt);
      const char* sep = " ";
      for (const PlacementSectorInfo& info : kPlacementSectorCatalogue) {
        const SectorFigures& f = sectors[static_cast<size_t>(info.sector)];
        if (f.n == 0) {
          std::printf("%s%s none", sep, info.name);
        } else {
          std::printf("%s%s %.1f%% over %zu (%zu predicted at rest)", sep, info.name, f.mape_pct,
                      f.n, f.n_predicted_rest);
        }
        sep = "; ";
      }
    }
  }
  if (!m.moved_by_tilt.empty()) {
    std::printf("\n  set in motion (moved at least 1 cm):");
    const char* sep = " ";
    for (const auto& [tilt, counts] : m.moved_by_tilt) {
      std::printf("%s%g deg %zu of %zu", sep, tilt, counts.first, counts.second);
      sep = "; ";
    }
  }
  std::printf("\n  written to %s\n", out.c_str());
}

void run_identify(IdentifyArgs a) {
  IdentificationOptions& o = a.options;
  o.sindy.method =
      with_flags({{"sindy.method", "--method"}}, [&] { return parse_sindy_method(a.method); });
  if (!a.terms.empty()) {
    o.sindy.terms =
        with_flags({{"sindy.terms", "--terms"}}, [&] { return parse_sindy_terms(a.terms); });
  }
  o.pairs.repair_glitches = !a.no_glitch_repair;
  require_range(o.sindy.lambda, 0, 10, "--lambda", "a threshold in [0, 10]");
  require_range(o.sindy.bootstraps, 1, 10000, "--bootstraps", "a count in [1, 10000]");
  require_range(o.pairs.smoothing_half_window, 0, 50, "--smooth",
                "a half window in [0, 50] samples");
  require_range(o.pairs.stationary_speed_mps, 0, 1, "--stationary-speed", "a speed in [0, 1] m/s");
  require_range(o.pairs.transient_s, 0, 60, "--skip-transient", "seconds in [0, 60]");
  require_range(a.max_direction_error_deg, 1, 180, "--max-direction-error",
                "an angle in [1, 180] deg");
  o.pairs.max_direction_error_rad = deg_to_rad(a.max_direction_error_deg);
  if (a.data.empty() == a.series.empty()) {
    throw UsageError("give either a trajectory CSV (positional FILE) or --series FILE, not " +
                     std::string(a.data.empty() ? "neither" : "both"));
  }
  if (!a.series.empty() && !a.table.empty()) {
    throw UsageError("--table applies to trajectory data; a speed series already holds vair");
  }
  ensure_parent_dir(a.out);

  IdentifiedModel model;
  if (!a.series.empty()) {
    model = identify_series(read_speed_series_csv(a.series), a.object, o);
    model.source = a.series;
  } else {
    const TrajectoryFiles files = read_trajectory_files(a.data);
    const TrajectorySet& set = files.set;
    std::set<std::string> objects;
    for (const Trajectory& tr : set.trajectories) objects.insert(tr.object);
    if (a.object.empty()) {
      if (objects.size() > 1) {
        std::string list;
        for (const std::string& name : objects) list += (list.empty() ? "" : ", ") + name;
        throw UsageError(files.source + " holds several object types (" + list +
                         "); choose one with --object");
      }
      a.object = *objects.begin();
    } else if (!objects.count(a.object)) {
      throw InputError(files.source + ": no trajectory of object type '" + a.object + "'");
    }
    const AirFieldModel field = field_model_or_default(a.table);
    model = identify_trajectories(set, a.object, field, o);
    model.source = files.source;
  }
  write_text_file(a.out, identified_model_json(model));
  print_summary(model, a.out);
}

}  // namespace

void add_identify_command(CLI::App& app) {
  auto args = std::make_shared<IdentifyArgs>();
  CLI::App* sub = app.add_subcommand(
      "identify",
      "Identify an object's speed dynamics with SINDy (section IV, Appendix D): from a\n"
      "trajectory CSV (traj,object,t,x,y,pan_deg,tilt_deg[,group]) or a speed series\n"
      "(--series: t,v,vair). Speeds by central differences after glitch repair, air speed from\n"
      "the field model, stationary samples dropped, Savitzky-Golay smoothing, then sparse\n"
      "regression in discrete time over the library 1, v, vair, v^2, v*vair, vair^2, v^3,\n"
      "v^2*vair, v*vair^2, vair^3. Writes model.json (continuous-time coefficients, inclusion\n"
      "probabilities, R^2, end-position MAPE). Method: docs/identification.md.");
  sub->add_option(
      "FILE", args->data,
      "Trajectory CSV (see docs/data_formats.md), or several (e.g. Appendix D sessions\n"
      "recorded apart): trajectory ids then become FILE_INDEX:ID, 1-based");
  sub->add_option("--series", args->series, "Speed series CSV with header t,v,vair instead");
  sub->add_option("--out", args->out, "Output model JSON")->required();
  sub->add_option("--table", args->table,
                  std::string("Coefficient table CSV or field-model JSON for the air speed; ") +
                      kDefaultFieldModelHelp);
  sub->add_option("--object", args->object,
                  "Object type to identify (required when the file holds several)");
  sub->add_option("--method", args->method, "stlsq | esindy | robust | robust-esindy")
      ->capture_default_str();
  IdentificationOptions& o = args->options;
  sub->add_option("--lambda", o.sindy.lambda,
                  "Threshold on the discrete-time coefficients (sequential thresholding)")
      ->capture_default_str();
  sub->add_option("--bootstraps", o.sindy.bootstraps, "E-SINDy bootstrap count")
      ->capture_default_str();
  sub->add_option("--seed", o.sindy.seed, "Seed of the bootstraps")->capture_default_str();
  sub->add_option("--smooth", o.pairs.smoothing_half_window,
                  "Savitzky-Golay half window in samples (cubic; 0: no smoothing)")
      ->capture_default_str();
  sub->add_option("--stationary-speed", o.pairs.stationary_speed_mps,
                  "Speeds below this (m/s) count as at rest and are dropped")
      ->capture_default_str();
  sub->add_option("--skip-transient", o.pairs.transient_s,
                  "Seconds after a command change (and after each trajectory's first frame) whose "
                  "samples are not used: the jet is still sweeping there")
      ->capture_default_str();
  sub->add_option("--max-direction-error", args->max_direction_error_deg,
                  "Moving samples more than this (deg) off the radial direction from s are not "
                  "used (eq. 9); 180 keeps all")
      ->capture_default_str();
  sub->add_option("--terms", args->terms,
                  "Library terms the regression may use, comma-separated (default: all ten), e.g.\n"
                  "1,v,vair for eq. (8)'s structure when the data cannot tell structures apart\n"
                  "(docs/identification.md); must include v");
  sub->add_flag("--no-glitch-repair", args->no_glitch_repair,
                "Do not repair single-frame position glitches before differencing");
  sub->callback([args] { run_identify(*args); });
}

}  // namespace airtwin::cli
