// airtwin field: the air on the floor for one nozzle orientation on a grid centred on the origin,
// as CSV (x,y,vx,vy,speed), optionally as a field grid for `airtwin fitfield --cfd`
// (pan_deg,tilt_deg,x,y,speed,vx,vy) and as a PNG picture: the analytical model (eqs. 1-3, the
// default) or the CFD of the jet (data/cfd/, models/cfd_field.h).

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "app/cfd_source.h"
#include "app/cli_common.h"
#include "app/commands.h"
#include "common/errors.h"
#include "common/units.h"
#include "models/air_field.h"
#include "models/cfd_field.h"
#include "models/field_grid.h"
#include "models/field_model_file.h"
#include "plots/field_plot.h"

namespace airtwin::cli {
namespace {

struct FieldArgs {
  double pan_deg = 0.0;
  double tilt_deg = 0.0;
  std::string table;
  double extent_m = 2.0;
  double step_m = 0.02;
  std::string out;
  std::string png;
  std::string fit_grid;
  std::string source = "model";
  std::string cfd_dir = AIRTWIN_CFD_DIR;
  double height_m = 0.015;
};

constexpr long kMaxGridPoints = 25'000'000;

void run_field(const FieldArgs& a) {
  require_range(a.pan_deg, -360, 360, "--pan", "a pan angle in [-360, 360] deg");
  // The range every field model can serve: below the fold of eq. (2) with the paper's a1, a2
  // (64.4 deg), the lowest of the shipped models' folds (the CFD-fitted one folds at 88.7 deg).
  const double fold_deg = rad_to_deg(fold_tilt_rad(NozzleGeometry{}));
  if (!(a.tilt_deg >= 0 && a.tilt_deg < fold_deg)) {
    throw UsageError("--tilt: expected a tilt in [0, " + std::to_string(fold_deg) +
                     ") deg (eq. (2) with the paper's a1, a2 folds back beyond it), got " +
                     std::to_string(a.tilt_deg));
  }
  require_range(a.extent_m, 1e-3, 100, "--extent", "a grid side in (0, 100] m");
  require_range(a.step_m, 1e-4, a.extent_m, "--step", "a grid step in [1e-4 m, extent]");

  if (a.source != "model" && a.source != "cfd") {
    throw UsageError("--source: expected model or cfd, got '" + a.source + "'");
  }
  const bool cfd = a.source == "cfd";
  if (!cfd && (a.cfd_dir != AIRTWIN_CFD_DIR || a.height_m != 0.015)) {
    throw UsageError("--cfd and --height need --source cfd");
  }
  if (cfd && !a.table.empty()) throw UsageError("--table is the model's; not with --source cfd");
  require_range(a.height_m, 1e-4, 0.1, "--height", "a height above the floor in (0, 0.1] m");
  const NozzleOrientation orientation{deg_to_rad(a.pan_deg), deg_to_rad(a.tilt_deg)};
  const AirFieldModel model = field_model_or_default(a.table);
  const OrientedField field = model.at(orientation);
  std::optional<CfdField> cfd_field;
  if (cfd) {
    cfd_field = read_cfd_source(a.cfd_dir);
    cfd_field->stagnation_point(orientation);  // a tilt outside the cases: one clear error now
  }

  // A symmetric grid through the origin: nodes at k * step, |k * step| <= extent / 2.
  const long half = static_cast<long>(std::floor(0.5 * a.extent_m / a.step_m + 1e-9));
  const long n = 2 * half + 1;
  if (n * n > kMaxGridPoints) {
    throw UsageError("--step: " + std::to_string(n) + " x " + std::to_string(n) +
                     " grid points is more than the limit of " + std::to_string(kMaxGridPoints) +
                     "; use a larger --step or a smaller --extent");
  }
  plots::VectorFieldGrid grid;
  grid.x.resize(n);
  for (long i = 0; i < n; ++i) grid.x[i] = static_cast<double>(i - half) * a.step_m;
  grid.y = grid.x;
  grid.vx.resize(n, n);
  grid.vy.resize(n, n);
  grid.speed.resize(n, n);

  // Evaluate row by row with the batch API.
  Eigen::Matrix2Xd p(2, n);
  Eigen::Matrix2Xd v(2, n);
  p.row(0) = grid.x.transpose();
  std::string csv = "x,y,vx,vy,speed\n";
  csv.reserve(static_cast<size_t>(n * n) * 48);
  FieldGrid fit_grid;  // the same samples with their orientation, for fitfield
  fit_grid.source = a.fit_grid;
  fit_grid.kind = GridKind::kSimulated;
  char line[128];
  for (long j = 0; j < n; ++j) {
    p.row(1).setConstant(grid.y[j]);
    if (cfd) {
      for (long i = 0; i < n; ++i) {
        v.col(i) = cfd_field->at(orientation, p.col(i), a.height_m).u_W;
      }
    } else {
      field.velocities(p, v);
    }
    for (long i = 0; i < n; ++i) {
      const double vx = v(0, i), vy = v(1, i), speed = std::hypot(vx, vy);
      grid.vx(j, i) = vx;
      grid.vy(j, i) = vy;
      grid.speed(j, i) = speed;
      std::snprintf(line, sizeof line, "%.6f,%.6f,%.6f,%.6f,%.6f\n", grid.x[i], grid.y[j], vx, vy,
                    speed);
      csv += line;
      if (!a.fit_grid.empty()) {
        FieldSample sample;
        sample.orientation = orientation;
        sample.p_W = {grid.x[i], grid.y[j]};
        sample.speed_mps = speed;
        sample.v_W = {vx, vy};
        fit_grid.samples.push_back(sample);
      }
    }
  }
  write_text_file(a.out, csv);
  if (!a.fit_grid.empty()) write_text_file(a.fit_grid, field_grid_to_csv(fit_grid));

  const Eigen::Vector2d s = cfd ? cfd_field->stagnation_point(orientation)
                                : field.stagnation_point(),
                        c = field.projection_point();
  std::printf(
      "field (%s): pan %.3f deg, tilt %.3f deg: c = (%.4f, %.4f) m, s = (%.4f, %.4f) m, "
      "max speed %.3f m/s on %ldx%ld grid -> %s\n",
      a.source.c_str(), a.pan_deg, a.tilt_deg, c.x(), c.y(), s.x(), s.y(), grid.speed.maxCoeff(), n,
      n, a.out.c_str());
  if (!a.png.empty()) {
    plots::FieldMarks marks;
    marks.stagnation_W = s;
    marks.projection_W = c;
    char title[128];
    std::snprintf(title, sizeof title, "air field (%s), pan %.1f deg, tilt %.1f deg",
                  a.source.c_str(), a.pan_deg, a.tilt_deg);
    marks.title = title;
    ensure_parent_dir(a.png);
    plots::write_field_png(grid, marks, a.png);
    std::printf("field: picture -> %s\n", a.png.c_str());
  }
}

}  // namespace

void add_field_command(CLI::App& app) {
  auto args = std::make_shared<FieldArgs>();
  CLI::App* sub = app.add_subcommand(
      "field",
      "Evaluate the analytical air field (eqs. 1-3) for one nozzle orientation on a grid\n"
      "centred on the origin, or the jet's CFD (--source cfd); write CSV x,y,vx,vy,speed (m, "
      "m/s),\n"
      "optionally the same as a grid for 'airtwin fitfield --cfd' (--fit-grid) and a PNG.");
  sub->add_option("--pan", args->pan_deg, "Nozzle pan angle theta in degrees")->required();
  sub->add_option("--tilt", args->tilt_deg, "Nozzle tilt angle phi in degrees (0 = straight down)")
      ->required();
  sub->add_option(
      "--table", args->table,
      std::string("Coefficient table CSV (tilt_deg,alpha_deg,b1,b2,b3) or field-model JSON (eq.\n"
                  "(2)'s a1, a2 and a table); ") +
          kDefaultFieldModelHelp);
  sub->add_option("--extent", args->extent_m, "Side of the square grid in metres")
      ->capture_default_str();
  sub->add_option("--step", args->step_m, "Grid spacing in metres")->capture_default_str();
  sub->add_option("--out", args->out, "Output CSV file")->required();
  sub->add_option(
         "--source", args->source,
         "model: eqs. (1)-(3) with the table; cfd: the jet's CFD (data/cfd/, docs/cfd.md), "
         "interpolated between its tilts")
      ->capture_default_str();
  sub->add_option("--cfd", args->cfd_dir,
                  "With --source cfd: the folder of CFD cases, or one case's .json header (that "
                  "tilt only, e.g. the held-out 37.5 deg)")
      ->capture_default_str();
  sub->add_option("--height", args->height_m,
                  "With --source cfd: height above the floor in metres (the data: 4-25 mm)")
      ->capture_default_str();
  sub->add_option("--png", args->png, "Also write a picture of the field (PNG)");
  sub->add_option("--fit-grid", args->fit_grid,
                  "Also write the samples as a field grid for 'airtwin fitfield --cfd': "
                  "pan_deg,tilt_deg,x,y,speed,vx,vy (deg, m, m/s; speed = |(vx, vy)|)");
  sub->callback([args] { run_field(*args); });
}

}  // namespace airtwin::cli
