#include "sim/drag_calibration.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "common/errors.h"
#include "common/quantile.h"
#include "common/text.h"
#include "sim/dynamics_calibration.h"

namespace airtwin {
namespace {

ObjectTypeParameters& type_of(CollectionOptions& c) {
  return c.object == "tracer" ? c.twin.scene.tracer : c.twin.scene.cotton;
}

// The grid of one axis between lo and hi (lo alone when they are equal).
std::vector<double> grid(double lo, double hi, int points) {
  if (points <= 1 || lo == hi) return {lo};
  std::vector<double> out;
  // Rounded to nine digits: 0.2, not 0.19999999999999998, in records and on the command line.
  for (int i = 0; i < points; ++i) {
    out.push_back(std::round((lo + (hi - lo) * i / (points - 1)) * 1e9) / 1e9);
  }
  return out;
}

}  // namespace

void DragCalibrationOptions::validate() const {
  collection.validate();
  target.validate("calibration target");
  const SceneParameters& scene = collection.twin.scene;
  if ((collection.object == "tracer" ? scene.tracer : scene.cotton).drag_law !=
      DragLaw::kPhysical) {
    throw FieldError("calibration.object",
                     "the " + collection.object + "'s drag law must be the physical one");
  }
  if (axes.empty()) throw FieldError("calibration.axes", "expected at least one axis");
  if (refinements < 0 || refinements > 5) {
    throw FieldError("calibration.refinements", "expected 0 to 5");
  }
  for (size_t i = 0; i < axes.size(); ++i) {
    const DragCalibrationAxis& a = axes[i];
    const ObjectPhysicsSpec& spec = object_physics_catalogue()[static_cast<size_t>(a.key)];
    const std::string where = "axis " + std::to_string(i + 1) + " (" + spec.key + "): ";
    if (!(a.min >= spec.min && a.max <= spec.max && a.min <= a.max)) {
      throw FieldError("calibration.axes", where + "window [" + format_number(a.min) + ", " +
                                               format_number(a.max) + "] is not inside [" +
                                               format_number(spec.min) + ", " +
                                               format_number(spec.max) + "]");
    }
    if (a.points < 1 || a.points > 9 || (a.points == 1) != (a.min == a.max)) {
      throw FieldError("calibration.axes",
                       where + "expected 2 to 9 points over a window, or 1 for a fixed value");
    }
    for (size_t j = 0; j < i; ++j) {
      if (axes[j].key == a.key) throw FieldError("calibration.axes", where + "given twice");
    }
  }
}

std::string active_terms(const IdentifiedModel& model) {
  std::string out;
  for (int j = 0; j < kSindyTerms; ++j) {
    if (model.coefficients[j] != 0.0) {
      if (!out.empty()) out += ',';
      out += kTermNames[static_cast<size_t>(j)];
    }
  }
  return out;
}

DragCalibrationPoint evaluate_drag_point(const DragCalibrationOptions& o,
                                         const std::vector<double>& values,
                                         const AirFieldModel& field) {
  AIRTWIN_DEMAND(values.size() == o.axes.size());
  CollectionOptions collection = o.collection;
  for (size_t i = 0; i < values.size(); ++i) {
    set_object_physics_value(o.axes[i].key, values[i], &type_of(collection));
  }
  const TrajectorySet data = run_collection(collection, field);

  DragCalibrationPoint p;
  p.values = values;
  IdentificationOptions fixed = o.identification;
  fixed.sindy.terms = parse_sindy_terms("1,v,vair");
  const IdentifiedModel m = identify_trajectories(data, collection.object, field, fixed);
  p.eq8_form = {m.coefficients[1], m.coefficients[2], m.coefficients[0]};
  p.r2 = m.r2;
  p.end_position_mape_pct = m.end_position_mape_pct.value_or(NAN);
  p.mape_by_tilt_pct = m.end_position_mape_by_tilt_pct;
  p.by_sector = m.end_position_by_sector;
  const ObjectDynamics& t = o.target;
  p.worst_relative_error =
      std::max({std::abs(p.eq8_form.xi1 / t.xi1 - 1.0), std::abs(p.eq8_form.xi2 / t.xi2 - 1.0),
                std::abs(p.eq8_form.xi3 / t.xi3 - 1.0)});
  if (!std::isfinite(p.worst_relative_error)) {
    p.worst_relative_error = std::numeric_limits<double>::infinity();
  }
  const IdentifiedModel full =
      identify_trajectories(data, collection.object, field, o.identification);
  p.full_library_terms = active_terms(full);
  p.full_library_is_eq8 = p.full_library_terms == "1,v,vair";
  return p;
}

DragCalibration calibrate_drag(
    const DragCalibrationOptions& o, const AirFieldModel& field,
    const std::function<void(const DragCalibrationPoint&, size_t)>& progress) {
  o.validate();
  DragCalibration result;
  std::vector<double> lo, hi, step;
  std::vector<int> points;
  for (const DragCalibrationAxis& a : o.axes) {
    lo.push_back(a.min);
    hi.push_back(a.max);
    points.push_back(a.points);
    step.push_back(a.points > 1 ? (a.max - a.min) / (a.points - 1) : 0.0);
  }
  const auto run_grid = [&](const std::vector<double>& from, const std::vector<double>& to) {
    std::vector<std::vector<double>> axes_values;
    size_t total = 1;
    for (size_t i = 0; i < from.size(); ++i) {
      axes_values.push_back(grid(from[i], to[i], points[i]));
      total *= axes_values.back().size();
    }
    for (size_t n = 0; n < total; ++n) {
      std::vector<double> v(from.size());
      size_t rest = n;
      for (size_t i = 0; i < from.size(); ++i) {
        v[i] = axes_values[i][rest % axes_values[i].size()];
        rest /= axes_values[i].size();
      }
      // A refined grid shares points with the coarser one: evaluate each point once.
      const bool seen = std::any_of(result.points.begin(), result.points.end(),
                                    [&](const DragCalibrationPoint& p) { return p.values == v; });
      if (seen) continue;
      result.points.push_back(evaluate_drag_point(o, v, field));
      const size_t i = result.points.size() - 1;
      if (result.points[i].worst_relative_error < result.points[result.best].worst_relative_error) {
        result.best = i;
      }
      if (progress) progress(result.points[i], i);
    }
  };
  run_grid(lo, hi);
  for (int r = 0; r < o.refinements; ++r) {
    // Half the spacing, centred on the best point, kept inside the windows.
    const std::vector<double> centre = result.points[result.best].values;
    std::vector<double> from(centre.size()), to(centre.size());
    for (size_t i = 0; i < centre.size(); ++i) {
      step[i] *= 0.5;
      const double half = 0.5 * step[i] * (points[i] - 1);
      from[i] = std::max(lo[i], centre[i] - half);
      to[i] = std::min(hi[i], centre[i] + half);
      if (to[i] - from[i] < 1e-12) to[i] = from[i];
    }
    run_grid(from, to);
  }
  result.best_repeatability_pct =
      drag_point_repeatability_pct(o, result.points[result.best].values, field);
  return result;
}

double drag_point_repeatability_pct(const DragCalibrationOptions& o,
                                    const std::vector<double>& values, const AirFieldModel& field) {
  AIRTWIN_DEMAND(values.size() == o.axes.size());
  // The paper's 8 placements at one tilt, six runs each.
  CollectionOptions rep = o.collection;
  for (size_t i = 0; i < o.axes.size(); ++i) {
    set_object_physics_value(o.axes[i].key, values[i], &type_of(rep));
  }
  rep.per_tilt = 8;
  rep.tilts_rad = {rep.tilts_rad.front()};
  double sum = 0.0;
  int n = 0;
  for (const CollectionTrial& trial : plan_collection(rep)) {
    const std::optional<double> mape = repeatability_mape_pct(trial, rep, field, 6);
    if (!mape) continue;
    sum += *mape;
    ++n;
  }
  return n > 0 ? sum / n : NAN;
}

std::vector<DragCalibrationCheck> check_drag_point(
    const DragCalibrationOptions& o, const std::vector<double>& values,
    const std::vector<std::uint64_t>& seeds, const AirFieldModel& field,
    const std::function<void(const DragCalibrationCheck&, size_t)>& progress) {
  o.validate();
  if (seeds.empty()) throw FieldError("calibration.held_out_seeds", "expected at least one seed");
  for (size_t i = 0; i < seeds.size(); ++i) {
    if (seeds[i] == o.collection.seed) {
      throw FieldError("calibration.held_out_seeds",
                       "seed " + std::to_string(seeds[i]) +
                           " is the calibration's own: a check needs collections it did not see");
    }
    if (std::find(seeds.begin(), seeds.begin() + static_cast<std::ptrdiff_t>(i), seeds[i]) !=
        seeds.begin() + static_cast<std::ptrdiff_t>(i)) {
      throw FieldError("calibration.held_out_seeds",
                       "seed " + std::to_string(seeds[i]) + " given twice");
    }
  }
  std::vector<DragCalibrationCheck> out;
  for (const std::uint64_t seed : seeds) {
    DragCalibrationOptions at = o;
    at.collection.seed = seed;
    DragCalibrationCheck c;
    c.seed = seed;
    c.point = evaluate_drag_point(at, values, field);
    c.repeatability_pct = drag_point_repeatability_pct(at, values, field);
    out.push_back(std::move(c));
    if (progress) progress(out.back(), out.size() - 1);
  }
  return out;
}

namespace {
DragCheckSpread spread_of(const std::vector<double>& v) {
  DragCheckSpread s;
  s.n = v.size();
  if (v.empty()) return s;
  s.median = quantile(v, 0.5);
  s.min = *std::min_element(v.begin(), v.end());
  s.max = *std::max_element(v.begin(), v.end());
  return s;
}
}  // namespace

DragCheckSummary summarize_checks(const std::vector<DragCalibrationCheck>& checks) {
  DragCheckSummary out;
  std::vector<double> worst, repeatability;
  std::map<double, std::vector<double>> mape;
  std::map<double, std::array<std::vector<double>, kPlacementSectors>> by_sector;
  for (const DragCalibrationCheck& k : checks) {
    if (std::isfinite(k.repeatability_pct)) repeatability.push_back(k.repeatability_pct);
    if (k.point.full_library_is_eq8) ++out.full_library_is_eq8;
    if (!k.air_term_kept()) {
      ++out.air_term_lost;
      continue;
    }
    worst.push_back(k.point.worst_relative_error);
    for (const auto& [tilt, m] : k.point.mape_by_tilt_pct) mape[tilt].push_back(m);
    for (const auto& [tilt, sectors] : k.point.by_sector) {
      for (size_t i = 0; i < kPlacementSectors; ++i) {
        if (sectors[i].n > 0) by_sector[tilt][i].push_back(sectors[i].mape_pct);
      }
    }
  }
  out.worst_relative_error = spread_of(worst);
  for (const auto& [tilt, v] : mape) out.mape_by_tilt_pct[tilt] = spread_of(v);
  for (const auto& [tilt, sectors] : by_sector) {
    for (size_t i = 0; i < kPlacementSectors; ++i) {
      out.mape_by_tilt_sector_pct[tilt][i] = spread_of(sectors[i]);
    }
  }
  out.repeatability_pct = spread_of(repeatability);
  return out;
}

}  // namespace airtwin
