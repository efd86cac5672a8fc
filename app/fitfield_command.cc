// airtwin fitfield: Appendix C. Fits the eq. (3) coefficient table to a measured (hot-wire) grid,
// optionally fused with a CFD grid, writes the table CSV and prints a JSON report of how well the
// fitted model agrees with each source (models/field_fit.h, docs/field_fitting.md). With
// --evaluate TABLE it fits nothing and reports the same agreement for a given table.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/cli_common.h"
#include "app/commands.h"
#include "common/errors.h"
#include "common/units.h"
#include "models/field_fit.h"
#include "models/field_grid.h"
#include "models/field_model_file.h"
#include "models/field_table.h"

namespace airtwin::cli {
namespace {

struct FitFieldArgs {
  std::string grid;
  std::string cfd;
  std::string out;
  std::string evaluate;
  std::string eq2;        // "A1,A2": eq. (2)'s coefficients; empty: the paper's
  std::string model_out;  // field-model JSON naming --out's table with eq. (2)'s a1, a2
  FieldFitOptions options;
};

// A number for the report, rounded to `decimals`; NaN (nothing to measure) becomes null.
nlohmann::ordered_json number(double v, int decimals) {
  if (!std::isfinite(v)) return nullptr;
  const double scale = std::pow(10.0, decimals);
  return std::round(v * scale) / scale;
}

// The agreement of a table with each source, one array entry per tilt (fit and --evaluate).
struct Agreement {
  nlohmann::ordered_json tilts, n_grid, n_cfd, mape_grid, mape_cfd, nm_grid, nm_cfd, rmse_grid,
      rmse_cfd, angle, n_angle;
};

Agreement agreement(const std::vector<TiltFitReport>& reports) {
  using json = nlohmann::ordered_json;
  Agreement g;
  for (json* v : {&g.tilts, &g.n_grid, &g.n_cfd, &g.mape_grid, &g.mape_cfd, &g.nm_grid, &g.nm_cfd,
                  &g.rmse_grid, &g.rmse_cfd, &g.angle, &g.n_angle}) {
    *v = json::array();
  }
  for (const TiltFitReport& r : reports) {
    g.tilts.push_back(number(rad_to_deg(r.tilt_rad), 6));
    g.mape_grid.push_back(number(r.grid.mape_pct, 4));
    g.mape_cfd.push_back(number(r.cfd.mape_pct, 4));
    g.n_grid.push_back(r.grid.n_samples);
    g.n_cfd.push_back(r.cfd.n_samples);
    g.nm_grid.push_back(r.grid.n_mape_samples);
    g.nm_cfd.push_back(r.cfd.n_mape_samples);
    g.rmse_grid.push_back(number(r.grid.rmse_mps, 6));
    g.rmse_cfd.push_back(number(r.cfd.rmse_mps, 6));
    g.angle.push_back(number(r.cfd_direction_error_deg, 4));
    g.n_angle.push_back(r.n_direction_samples);
  }
  return g;
}

nlohmann::ordered_json report_json(const FitFieldArgs& a, const FieldFitResult& fit) {
  using json = nlohmann::ordered_json;
  const FieldFitOptions& o = a.options;
  const Agreement g = agreement(fit.tilts);
  json bins = json::array(), start = json::array();
  json iterations = json::array(), evaluations = json::array(), status = json::array(),
       converged = json::array(), warnings = json::array();
  for (const TiltFitReport& r : fit.tilts) {
    const double tilt_deg = rad_to_deg(r.tilt_rad);
    bins.push_back(r.alpha_bins_with_data);
    start.push_back({{"b1", number(r.start_profile.b1, 8)},
                     {"b2", number(r.start_profile.b2, 8)},
                     {"b3", number(r.start_profile.b3, 8)}});
    iterations.push_back(r.lm_iterations);
    evaluations.push_back(r.lm_evaluations);
    status.push_back(r.lm_status);
    converged.push_back(r.lm_converged);

    // What a reader of the table should know about this tilt.
    char w[256];
    if (!r.lm_converged) {
      std::snprintf(w, sizeof w, "tilt %g deg: the optimiser stopped before converging (%s)",
                    tilt_deg, r.lm_status.c_str());
      warnings.push_back(w);
    }
    if (r.grid.n_samples == 0 || (!a.cfd.empty() && r.cfd.n_samples == 0)) {
      std::snprintf(w, sizeof w, "tilt %g deg: only the %s covers this tilt, no fusion", tilt_deg,
                    r.grid.n_samples == 0 ? "CFD" : "measured grid");
      warnings.push_back(w);
    }
    if (r.alpha_bins_with_data < FieldTable::kAlphaBins * 9 / 10) {
      std::snprintf(w, sizeof w,
                    "tilt %g deg: %d of 360 one-degree directions hold no sample; their "
                    "coefficients follow from the neighbouring directions",
                    tilt_deg, FieldTable::kAlphaBins - r.alpha_bins_with_data);
      warnings.push_back(w);
    }
  }
  char mape_text[200];
  std::snprintf(mape_text, sizeof mape_text,
                "mean of |v_model - v| / v * 100 over samples with data speed v >= %g m/s (the "
                "hot-wire's lower detection limit); v_model is the written table evaluated by "
                "the air-field model",
                o.mape_min_speed_mps);
  char angle_text[200];
  std::snprintf(angle_text, sizeof angle_text,
                "mean angle between the CFD velocity (vx, vy) and the model's radial direction "
                "from s, over CFD samples with |(vx, vy)| >= %g m/s",
                o.mape_min_speed_mps);
  return {
      {"command", "fitfield"},
      {"inputs", {{"grid", a.grid}, {"cfd", a.cfd.empty() ? json(nullptr) : json(a.cfd)}}},
      {"out", a.out},
      {"tilts_deg", g.tilts},
      {"n_points", {{"grid", g.n_grid}, {"cfd", g.n_cfd}}},
      {"mape_pct", {{"grid", g.mape_grid}, {"cfd", g.mape_cfd}}},
      {"n_mape_points", {{"grid", g.nm_grid}, {"cfd", g.nm_cfd}}},
      {"mape_min_speed_mps", o.mape_min_speed_mps},
      {"mape_definition", mape_text},
      {"rmse_mps", {{"grid", g.rmse_grid}, {"cfd", g.rmse_cfd}}},
      {"cfd_direction_error_deg", g.angle},
      {"n_direction_points", g.n_angle},
      {"direction_definition", angle_text},
      {"alpha_bins_with_data", bins},
      {"fusion",
       {{"cfd_weight", "L^2 / (L^2 + r^2) / N_cfd"},
        {"grid_weight", "r^2 / (L^2 + r^2) / N_grid"},
        {"r", "distance from the stagnation point s (m)"},
        {"N", "samples of that source at that tilt"},
        {"length_m", o.fusion_length_m}}},
      {"smoothing_deg", o.smoothing_deg},
      {"start_profile", start},
      {"optimizer",
       {{"method",
         "Eigen LevenbergMarquardt, sparse Jacobian (SparseQR), 1080 parameters per tilt"},
        {"iterations", iterations},
        {"evaluations", evaluations},
        {"status", status},
        {"converged", converged}}},
      {"warnings", warnings},
  };
}

// The report of --evaluate: the agreement of a given table with the grids, per tilt.
nlohmann::ordered_json evaluation_json(const FitFieldArgs& a,
                                       const std::vector<TiltFitReport>& reports) {
  using json = nlohmann::ordered_json;
  const Agreement g = agreement(reports);
  char mape_text[200];
  std::snprintf(mape_text, sizeof mape_text,
                "mean of |v_model - v| / v * 100 over samples with data speed v >= %g m/s; "
                "v_model is the table evaluated by the air-field model",
                a.options.mape_min_speed_mps);
  return {
      {"command", "fitfield --evaluate"},
      {"table", a.evaluate},
      {"inputs",
       {{"grid", a.grid.empty() ? json(nullptr) : json(a.grid)},
        {"cfd", a.cfd.empty() ? json(nullptr) : json(a.cfd)}}},
      {"tilts_deg", g.tilts},
      {"n_points", {{"grid", g.n_grid}, {"cfd", g.n_cfd}}},
      {"mape_pct", {{"grid", g.mape_grid}, {"cfd", g.mape_cfd}}},
      {"n_mape_points", {{"grid", g.nm_grid}, {"cfd", g.nm_cfd}}},
      {"mape_min_speed_mps", a.options.mape_min_speed_mps},
      {"mape_definition", mape_text},
      {"rmse_mps", {{"grid", g.rmse_grid}, {"cfd", g.rmse_cfd}}},
      {"cfd_direction_error_deg", g.angle},
  };
}

// One top-level key per line, each value compact: readable, and still plain JSON.
void print_report(const nlohmann::ordered_json& report) {
  std::string text = "{\n";
  for (auto it = report.begin(); it != report.end(); ++it) {
    text += "  " + nlohmann::json(it.key()).dump() + ": " + it.value().dump();
    text += std::next(it) == report.end() ? "\n" : ",\n";
  }
  std::printf("%s}\n", text.c_str());
}

void run_fitfield(FitFieldArgs a) {
  FieldFitOptions& o = a.options;
  require_range(o.fusion_length_m, 1e-3, 100, "--fusion-length", "a length in [0.001, 100] m");
  require_range(o.smoothing_deg, 1, 180, "--smoothing", "an angle in [1, 180] deg");
  require_range(o.mape_min_speed_mps, 0, 100, "--mape-min-speed", "a speed in [0, 100] m/s");
  require_range(o.threads, 0, 256, "--threads", "a thread count in [0, 256] (0: all cores)");
  require_range(o.max_evaluations, 1, 100000, "--max-evaluations", "a count in [1, 100000]");
  require_range(o.time_budget_s, 0.01, 86400, "--time-budget", "seconds in [0.01, 86400]");
  if (!a.eq2.empty()) {
    const Eigen::Vector2d c = parse_xy(a.eq2, "--eq2");
    o.geometry.a1 = c.x();
    o.geometry.a2 = c.y();
    try {
      o.geometry.validate();
    } catch (const InputError& e) {
      throw UsageError(std::string("--eq2: ") + e.what());
    }
  }

  // --evaluate: no fit, the given table against whichever grids are given.
  if (!a.evaluate.empty()) {
    if (!a.out.empty() || !a.model_out.empty()) {
      throw UsageError("--out, --model-out: nothing is written with --evaluate");
    }
    if (a.grid.empty() && a.cfd.empty()) throw UsageError("--evaluate needs --grid or --cfd");
    FieldGrid grid, cfd;
    if (!a.grid.empty()) grid = load_field_grid(a.grid, GridKind::kMeasured);
    if (!a.cfd.empty()) cfd = load_field_grid(a.cfd, GridKind::kSimulated);
    const AirFieldModel model = is_field_model_file(a.evaluate)
                                    ? read_air_field_model(a.evaluate)
                                    : AirFieldModel(o.geometry, FieldTable::load_csv(a.evaluate));
    if (is_field_model_file(a.evaluate) && !a.eq2.empty()) {
      throw UsageError("--eq2: the field-model JSON of --evaluate has its own");
    }
    o.geometry = model.geometry();
    const FieldTable& table = model.table();
    print_report(evaluation_json(a, evaluate_field_table(table, a.grid.empty() ? nullptr : &grid,
                                                         a.cfd.empty() ? nullptr : &cfd, o)));
    return;
  }
  if (a.grid.empty()) throw UsageError("--grid is required (unless --evaluate)");
  if (a.out.empty()) throw UsageError("--out is required (unless --evaluate)");

  const FieldGrid grid = load_field_grid(a.grid, GridKind::kMeasured);
  FieldGrid cfd;
  if (!a.cfd.empty()) cfd = load_field_grid(a.cfd, GridKind::kSimulated);
  ensure_parent_dir(a.out);

  const FieldFitResult fit = fit_field_table(grid, a.cfd.empty() ? nullptr : &cfd, o);
  fit.table.save_csv(a.out);
  if (!a.model_out.empty()) {
    ensure_parent_dir(a.model_out);
    const std::filesystem::path from = std::filesystem::path(a.model_out).parent_path();
    write_air_field_model(
        a.model_out, o.geometry,
        std::filesystem::relative(a.out, from.empty() ? std::filesystem::path(".") : from)
            .generic_string());
  }
  print_report(report_json(a, fit));
}

}  // namespace

void add_fitfield_command(CLI::App& app) {
  auto args = std::make_shared<FitFieldArgs>();
  CLI::App* sub = app.add_subcommand(
      "fitfield",
      "Fit the eq. (3) coefficient table (Appendix C) to a measured air-speed grid, optionally\n"
      "fused with a CFD grid: CFD dominates near the stagnation point s, the measurements far\n"
      "from it. Every sample carries its own pan and tilt; each tilt in the data becomes a table\n"
      "tilt (at least 3). Writes the table CSV (tilt_deg,alpha_deg,b1,b2,b3) and prints a JSON\n"
      "report: MAPE per tilt against each source, CFD direction vs the model's radial direction.\n"
      "--evaluate TABLE fits nothing: the same report for a given table against the grids.\n"
      "Method and file formats: docs/field_fitting.md.");
  sub->add_option("--grid", args->grid,
                  "Measured grid CSV: pan_deg,tilt_deg,x,y,speed (deg, m, m/s); required to fit");
  sub->add_option("--cfd", args->cfd,
                  "CFD grid CSV: pan_deg,tilt_deg,x,y,speed,vx,vy (deg, m, m/s)");
  sub->add_option("--out", args->out, "Output coefficient table CSV; required to fit");
  sub->add_option("--eq2", args->eq2,
                  "A1,A2: eq. (2)'s coefficients that place s for every sample (|c - s| = A1\n"
                  "|c|^A2); default: the paper's 0.1,2.33");
  sub->add_option("--model-out", args->model_out,
                  "Also write a field-model JSON: eq. (2)'s A1, A2 and --out's table, readable\n"
                  "wherever --table is (docs/data_formats.md)");
  sub->add_option("--evaluate", args->evaluate,
                  "Fit nothing: report the MAPE of this table (tilt_deg,alpha_deg,b1,b2,b3) "
                  "against --grid and/or --cfd");
  FieldFitOptions& o = args->options;
  sub->add_option("--fusion-length", o.fusion_length_m,
                  "L (m): CFD weight L^2/(L^2+r^2), grid weight r^2/(L^2+r^2) at distance r "
                  "from s")
      ->capture_default_str();
  sub->add_option("--smoothing", o.smoothing_deg,
                  "Angular smoothing (deg): coefficient ripples shorter than this are smoothed")
      ->capture_default_str();
  sub->add_option("--mape-min-speed", o.mape_min_speed_mps,
                  "MAPE and direction statistics count samples with speed >= this (m/s)")
      ->capture_default_str();
  sub->add_option("--threads", o.threads, "Tilts fitted in parallel (0: one per core)")
      ->capture_default_str();
  sub->add_option("--max-evaluations", o.max_evaluations,
                  "Levenberg-Marquardt function evaluations per tilt")
      ->capture_default_str();
  sub->add_option("--time-budget", o.time_budget_s,
                  "Seconds per tilt; a fit that runs out keeps its best answer and warns")
      ->capture_default_str();
  sub->callback([args] { run_fitfield(*args); });
}

}  // namespace airtwin::cli
