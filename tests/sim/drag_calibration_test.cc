// The search of physical drag parameters: its options' errors, the grid and its refinement, the
// best point being the closest, reruns giving the same numbers, and the identified drag growing
// with C_D as the physics says. Small collections in the model's air keep it fast; the campaign
// in the CFD's air is recorded in docs/twin.md.

#include "sim/drag_calibration.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "common/errors.h"
#include "models/object_dynamics.h"

namespace airtwin {
namespace {

DragCalibrationOptions small_options() {
  DragCalibrationOptions o;
  o.collection.per_tilt = 10;
  o.collection.seed = 5;
  o.collection.twin.scene.tracer.use_physical_drag();
  o.target = kTracerDynamics;
  o.axes = {{ObjectPhysicsKey::kDragCoefficient, 0.4, 1.2, 2},
            {ObjectPhysicsKey::kKineticFriction, 0.3, 0.3, 1}};
  o.refinements = 1;
  return o;
}

std::string field_of(const DragCalibrationOptions& o) {
  try {
    o.validate();
  } catch (const FieldError& e) {
    return e.field() + ": " + e.detail();
  }
  return "valid";
}

TEST(DragCalibration, BadOptionsNameTheirField) {
  EXPECT_EQ(field_of(small_options()), "valid");
  DragCalibrationOptions o = small_options();
  o.collection.twin.scene.tracer = ObjectTypeParameters::tracer();  // eq. (8) law
  EXPECT_EQ(field_of(o).rfind("calibration.object: ", 0), 0u) << field_of(o);
  o = small_options();
  o.axes[0].max = 4.0;  // beyond C_D's range [0.05, 3]
  EXPECT_EQ(field_of(o), "calibration.axes: axis 1 (cd): window [0.4, 4] is not inside [0.05, 3]");
  o = small_options();
  o.axes[0].points = 1;  // a window needs two points or more
  EXPECT_NE(field_of(o).find("axis 1 (cd): expected 2 to 9 points"), std::string::npos)
      << field_of(o);
  o = small_options();
  o.axes[1].key = ObjectPhysicsKey::kDragCoefficient;
  EXPECT_NE(field_of(o).find("given twice"), std::string::npos) << field_of(o);
  o = small_options();
  o.axes.clear();
  EXPECT_EQ(field_of(o).rfind("calibration.axes: ", 0), 0u);
  o = small_options();
  o.refinements = 9;
  EXPECT_EQ(field_of(o).rfind("calibration.refinements", 0), 0u);
}

TEST(DragCalibration, GridThenRefinementAndTheBestIsTheClosest) {
  const DragCalibrationOptions o = small_options();
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  size_t reported = 0;
  const DragCalibration c =
      calibrate_drag(o, field, [&](const DragCalibrationPoint&, size_t i) { reported = i + 1; });
  // Two C_D points, then a grid of half the spacing around the best: one new point beside it.
  ASSERT_EQ(c.points.size(), 3u);
  EXPECT_EQ(reported, 3u);
  EXPECT_EQ(c.points[0].values, (std::vector<double>{0.4, 0.3}));
  EXPECT_EQ(c.points[1].values, (std::vector<double>{1.2, 0.3}));
  // The refined grid spans half the spacing (0.4) from the better of the two, inside the window.
  const bool low_better = c.points[0].worst_relative_error <= c.points[1].worst_relative_error;
  EXPECT_NEAR(c.points[2].values[0], low_better ? 0.6 : 1.0, 1e-12);
  for (const DragCalibrationPoint& p : c.points) {
    EXPECT_GE(p.worst_relative_error, c.points[c.best].worst_relative_error);
    EXPECT_FALSE(p.full_library_terms.empty());
    EXPECT_EQ(p.full_library_is_eq8, p.full_library_terms == "1,v,vair");
  }
  // The point again: the same collection and identification, the same numbers.
  const DragCalibrationPoint again = evaluate_drag_point(o, c.points[1].values, field);
  EXPECT_EQ(again.eq8_form.xi1, c.points[1].eq8_form.xi1);
  EXPECT_EQ(again.eq8_form.xi3, c.points[1].eq8_form.xi3);
  EXPECT_EQ(again.full_library_terms, c.points[1].full_library_terms);
  // Three times the drag coefficient: a stronger speed damping is identified.
  EXPECT_LT(c.points[1].eq8_form.xi1, c.points[0].eq8_form.xi1);
  // The distance is the worst of the three relative errors.
  const ObjectDynamics& e = c.points[1].eq8_form;
  const double worst =
      std::max({std::abs(e.xi1 / o.target.xi1 - 1), std::abs(e.xi2 / o.target.xi2 - 1),
                std::abs(e.xi3 / o.target.xi3 - 1)});
  EXPECT_DOUBLE_EQ(c.points[1].worst_relative_error, worst);
  // The paper's repeatability measure at the best point: a percentage of the travel, finite.
  EXPECT_TRUE(std::isfinite(c.best_repeatability_pct));
  EXPECT_GE(c.best_repeatability_pct, 0.0);
  EXPECT_LT(c.best_repeatability_pct, 100.0);
}

// A check at another seed is what the search itself measures there: the same collection, fits
// and repeatability as calibrate_drag's point at that seed, and another collection than the
// calibration's.
TEST(DragCalibration, HeldOutChecksAreTheSearchesOwnFiguresAtOtherSeeds) {
  DragCalibrationOptions o = small_options();
  o.axes = {{ObjectPhysicsKey::kDragCoefficient, 0.8, 0.8, 1},
            {ObjectPhysicsKey::kKineticFriction, 0.3, 0.3, 1}};
  o.refinements = 0;
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  const std::vector<double> values = {0.8, 0.3};
  size_t reported = 0;
  const std::vector<DragCalibrationCheck> checks = check_drag_point(
      o, values, {6, 7}, field, [&](const DragCalibrationCheck&, size_t i) { reported = i + 1; });
  ASSERT_EQ(checks.size(), 2u);
  EXPECT_EQ(reported, 2u);
  EXPECT_EQ(checks[0].seed, 6u);
  EXPECT_EQ(checks[1].seed, 7u);
  for (const DragCalibrationCheck& k : checks)
    EXPECT_EQ(k.air_term_kept(), k.point.eq8_form.xi2 > 0.0);
  {
    const DragCalibrationCheck& k = checks[0];
    DragCalibrationOptions at = o;
    at.collection.seed = k.seed;
    const DragCalibration search = calibrate_drag(at, field);
    ASSERT_EQ(search.points.size(), 1u);
    EXPECT_EQ(k.point.values, values);
    EXPECT_EQ(k.point.eq8_form.xi1, search.points[0].eq8_form.xi1) << k.seed;
    EXPECT_EQ(k.point.eq8_form.xi2, search.points[0].eq8_form.xi2) << k.seed;
    EXPECT_EQ(k.point.eq8_form.xi3, search.points[0].eq8_form.xi3) << k.seed;
    EXPECT_EQ(k.point.full_library_terms, search.points[0].full_library_terms) << k.seed;
    EXPECT_EQ(k.point.mape_by_tilt_pct, search.points[0].mape_by_tilt_pct) << k.seed;
    EXPECT_TRUE(k.repeatability_pct == search.best_repeatability_pct ||
                (std::isnan(k.repeatability_pct) && std::isnan(search.best_repeatability_pct)))
        << k.seed;
  }
  // Two collections, two sets of trajectories: the identified coefficients differ.
  EXPECT_NE(checks[0].point.eq8_form.xi1, checks[1].point.eq8_form.xi1);

  // The summary against its definition: two values' median is their mean; a check without the
  // air term counts apart and leaves the coefficients' and MAPE's spread.
  std::vector<DragCalibrationCheck> two = checks;
  two[0].point.eq8_form.xi2 = 0.8;
  two[1].point.eq8_form.xi2 = 0.9;
  const DragCheckSummary both = summarize_checks(two);
  EXPECT_EQ(both.air_term_lost, 0);
  EXPECT_EQ(both.worst_relative_error.n, 2u);
  EXPECT_DOUBLE_EQ(both.worst_relative_error.median,
                   0.5 * (two[0].point.worst_relative_error + two[1].point.worst_relative_error));
  EXPECT_EQ(both.worst_relative_error.min,
            std::min(two[0].point.worst_relative_error, two[1].point.worst_relative_error));
  // Each placement sector's spread is over the checks that placed objects there.
  for (DragCalibrationCheck& k : two) k.point.by_sector.clear();
  two[0].point.by_sector[22.5][2] = {3, 80.0, 2};
  two[1].point.by_sector[22.5][2] = {2, 100.0, 2};
  two[0].point.by_sector[22.5][1] = {4, 20.0, 0};
  const DragCheckSummary sectors = summarize_checks(two);
  ASSERT_EQ(sectors.mape_by_tilt_sector_pct.size(), 1u);
  const auto& s22 = sectors.mape_by_tilt_sector_pct.at(22.5);
  EXPECT_EQ(s22[0].n, 0u);
  EXPECT_EQ(s22[1].n, 1u);
  EXPECT_EQ(s22[1].median, 20.0);
  EXPECT_EQ(s22[2].n, 2u);
  EXPECT_DOUBLE_EQ(s22[2].median, 90.0);
  EXPECT_EQ(s22[2].min, 80.0);
  EXPECT_EQ(s22[2].max, 100.0);
  two[1].point.eq8_form.xi2 = 0.0;
  two[1].repeatability_pct = NAN;
  const DragCheckSummary one = summarize_checks(two);
  EXPECT_EQ(one.air_term_lost, 1);
  EXPECT_EQ(one.worst_relative_error.n, 1u);
  EXPECT_EQ(one.worst_relative_error.median, two[0].point.worst_relative_error);
  EXPECT_EQ(one.repeatability_pct.n, std::isfinite(two[0].repeatability_pct) ? 1u : 0u);

  const auto field_of_check = [&](const std::vector<std::uint64_t>& seeds) {
    try {
      check_drag_point(o, values, seeds, field);
    } catch (const FieldError& e) {
      return e.field() + ": " + e.detail();
    }
    return std::string("accepted");
  };
  EXPECT_EQ(field_of_check({}), "calibration.held_out_seeds: expected at least one seed");
  EXPECT_EQ(field_of_check({6, 5}),
            "calibration.held_out_seeds: seed 5 is the calibration's own: a check needs "
            "collections it did not see");
  EXPECT_EQ(field_of_check({6, 6}), "calibration.held_out_seeds: seed 6 given twice");
}

}  // namespace
}  // namespace airtwin
