// The scenario loader (scenes/scenario.h): the six shipped scenarios against the paper's numbers
// (section V, Table I), recomputed here from what was loaded; the controller's defaults per task;
// and one test per class of bad input, each checking that the single message names the file, the
// line and the key path.

#include "scenes/scenario.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>

#include "common/errors.h"

namespace airtwin {
namespace {

Scenario load(const std::string& name) {
  return read_scenario(std::string(AIRTWIN_SOURCE_DIR) + "/scenes/" + name + ".yaml");
}

double polyline_length(const std::vector<Eigen::Vector2d>& path) {
  double length = 0.0;
  for (size_t i = 1; i < path.size(); ++i) length += (path[i] - path[i - 1]).norm();
  return length;
}

int count_type(const Scenario& s, const std::string& type) {
  return static_cast<int>(std::count_if(s.scene.objects.begin(), s.scene.objects.end(),
                                        [&](const ObjectSpec& o) { return o.type == type; }));
}

double max_pairwise(const Scenario& s) {
  double d = 0.0;
  for (const auto& a : s.scene.objects) {
    for (const auto& b : s.scene.objects) d = std::max(d, (a.p_W - b.p_W).norm());
  }
  return d;
}

double min_pairwise(const Scenario& s) {
  double d = 1e9;
  for (size_t i = 0; i < s.scene.objects.size(); ++i) {
    for (size_t j = i + 1; j < s.scene.objects.size(); ++j) {
      d = std::min(d, (s.scene.objects[i].p_W - s.scene.objects[j].p_W).norm());
    }
  }
  return d;
}

void expect_same(const CemParameters& a, const CemParameters& b) {
  EXPECT_EQ(a.search, b.search);
  EXPECT_EQ(a.horizon_s, b.horizon_s);
  EXPECT_EQ(a.penalty, b.penalty);
  EXPECT_EQ(a.min_distance_m, b.min_distance_m);
  EXPECT_EQ(a.mean0_m, b.mean0_m);
  EXPECT_EQ(a.variance0_m2, b.variance0_m2);
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.elite, b.elite);
  EXPECT_EQ(a.max_iterations, b.max_iterations);
  EXPECT_EQ(a.converged_variance_m2, b.converged_variance_m2);
  EXPECT_EQ(a.scan_step_m, b.scan_step_m);
  EXPECT_EQ(a.predict_transition, b.predict_transition);
  EXPECT_EQ(a.sweep_clearance_m, b.sweep_clearance_m);
  EXPECT_EQ(a.keep_cheapest, b.keep_cheapest);
}

// What every shipped file adds to the paper's search (docs/scenario_schema.md): J_P for a re-aim
// sweeping past an object within delta_min, and the cheaper of the final mean and the cheapest
// candidate.
CemParameters with_shipped_additions(CemParameters p) {
  p.sweep_clearance_m = 0.10;
  p.keep_cheapest = true;
  return p;
}

// The single-tracer files carry the paper's single-object CEM (section V-B), written out here
// from the paper rather than from the code's defaults.
CemParameters single_object_cem() {
  CemParameters p;
  p.search = CemSearch::kLine;
  p.horizon_s = 1.5;
  p.penalty = 1000.0;
  p.min_distance_m = 0.10;
  p.mean0_m = 0.418;
  p.variance0_m2 = 20.9e-4;
  p.samples = 25;
  p.elite = 3;
  p.max_iterations = 5;
  p.converged_variance_m2 = 0.3e-4;
  p.scan_step_m = 0.0;  // never scans
  return p;
}

void expect_common(const Scenario& s, const std::string& name, double paper_completion_s) {
  EXPECT_EQ(s.name, name);
  EXPECT_NE(s.description.find("Kopitca"), std::string::npos) << s.description;
  EXPECT_EQ(s.scene.source, s.source);
  // Room to finish: the limit is well above the paper's completion time.
  EXPECT_GT(s.task.time_limit_s, 1.2 * paper_completion_s);
  // Everything starts on the floor the camera sees, within ~0.8 m of the origin.
  for (const ObjectSpec& o : s.scene.objects) EXPECT_LT(o.p_W.norm(), 0.8) << o.id;
}

TEST(Scenario, LineIsThePapersShortestPathFromItsFirstPoint) {
  const Scenario s = load("line");
  expect_common(s, "line", 38.0);
  ASSERT_EQ(s.scene.objects.size(), 1u);
  EXPECT_EQ(s.scene.objects[0].type, "tracer");
  EXPECT_EQ(s.task.kind, TaskKind::kPath);
  EXPECT_NEAR(polyline_length(s.task.path_W), 0.52, 1e-9);
  EXPECT_LT((s.scene.objects[0].p_W - s.task.path_W.front()).norm(), 1e-9);
  EXPECT_FALSE(s.task.vertices_as_references);
  EXPECT_DOUBLE_EQ(s.task.reference_spacing_m, 0.10);
  EXPECT_DOUBLE_EQ(s.task.switch_distance_m, 0.04);
  // 0.52 m every 0.10 m: 0.1 ... 0.5 and the end.
  EXPECT_EQ(path_references(s.task).size(), 6u);
  expect_same(s.controller, with_shipped_additions(single_object_cem()));
  EXPECT_DOUBLE_EQ(s.loop.settle_s, 0.3);
  EXPECT_DOUBLE_EQ(s.loop.latency_s, 0.0);
}

TEST(Scenario, SquareIsClosedWithThePapersLongestPerimeter) {
  const Scenario s = load("square");
  expect_common(s, "square", 154.0);
  ASSERT_EQ(s.scene.objects.size(), 1u);
  ASSERT_EQ(s.task.path_W.size(), 5u);  // four corners and back to the first
  EXPECT_LT((s.task.path_W.back() - s.task.path_W.front()).norm(), 1e-12);
  EXPECT_NEAR(polyline_length(s.task.path_W), 2.09, 0.02);
  for (size_t i = 1; i < 5; ++i) {
    EXPECT_NEAR((s.task.path_W[i] - s.task.path_W[i - 1]).norm(), 0.52, 0.01);
  }
  EXPECT_LT((s.scene.objects[0].p_W - s.task.path_W.front()).norm(), 1e-9);
  expect_same(s.controller, with_shipped_additions(single_object_cem()));
}

TEST(Scenario, LetterAIsOnePolylineOfAboutOneAndAHalfMetres) {
  const Scenario s = load("letter_A");
  expect_common(s, "letter_A", 108.0);
  ASSERT_EQ(s.scene.objects.size(), 1u);
  const auto& p = s.task.path_W;
  ASSERT_EQ(p.size(), 5u);
  EXPECT_NEAR(polyline_length(p), 1.50, 0.05);
  // Apex above both feet, 50 cm high; the feet level.
  EXPECT_NEAR(p[1].y() - p[0].y(), 0.50, 1e-9);
  EXPECT_NEAR(p[0].y(), p[2].y(), 1e-9);
  // The third leg climbs back along the right stroke; the crossbar ends on the left stroke.
  const Eigen::Vector2d right = (p[1] - p[2]).normalized();
  EXPECT_NEAR((p[3] - p[2]).normalized().dot(right), 1.0, 1e-3);
  const Eigen::Vector2d left = (p[1] - p[0]).normalized();
  EXPECT_NEAR((p[4] - p[0]).normalized().dot(left), 1.0, 1e-3);
  EXPECT_NEAR(p[3].y(), p[4].y(), 1e-9);
  expect_same(s.controller, with_shipped_additions(single_object_cem()));
}

TEST(Scenario, OctagonTakesFourTracersCornerToCorner) {
  const Scenario s = load("octagon");
  expect_common(s, "octagon", 205.0);
  EXPECT_EQ(count_type(s, "tracer"), 4);
  EXPECT_TRUE(s.task.vertices_as_references);
  EXPECT_DOUBLE_EQ(s.task.switch_distance_m, 0.063);
  ASSERT_EQ(s.task.path_W.size(), 9u);
  EXPECT_LT((s.task.path_W.back() - s.task.path_W.front()).norm(), 1e-12);
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < 8; ++i) centre += s.task.path_W[i] / 8.0;
  for (size_t i = 0; i < 8; ++i) EXPECT_NEAR((s.task.path_W[i] - centre).norm(), 0.30, 1e-3);
  for (size_t i = 1; i < 9; ++i) {
    EXPECT_NEAR((s.task.path_W[i] - s.task.path_W[i - 1]).norm(), 2 * 0.3 * std::sin(M_PI / 8),
                1e-3);
  }
  EXPECT_EQ(path_references(s.task).size(), 8u);
  // A tight group around the first corner, about 5 cm apart.
  for (const ObjectSpec& o : s.scene.objects) {
    EXPECT_LT((o.p_W - s.task.path_W.front()).norm(), 0.05) << o.id;
  }
  EXPECT_NEAR(min_pairwise(s), 0.05, 0.005);
  // The paper's multi-object line search, with the floor scanned every 10 cm when it is blind.
  CemParameters expected = CemParameters::line_defaults();
  expected.scan_step_m = 0.1;
  expect_same(s.controller, with_shipped_additions(expected));
}

TEST(Scenario, AggregationScattersTwentyFiveTracersAroundTheZone) {
  const Scenario s = load("aggregation");
  expect_common(s, "aggregation", 105.0);
  EXPECT_EQ(count_type(s, "tracer"), 25);
  EXPECT_EQ(s.task.kind, TaskKind::kAggregation);
  EXPECT_DOUBLE_EQ(s.task.zone.radius_m, 0.37 / 2);
  EXPECT_LT(s.task.zone.centre_W.norm(), 0.1);
  EXPECT_NEAR(max_pairwise(s), 1.2, 0.05);
  EXPECT_GE(min_pairwise(s), 0.06);
  // Nothing starts inside the zone: there is work to do.
  for (const ObjectSpec& o : s.scene.objects) EXPECT_FALSE(s.task.zone.contains(o.p_W)) << o.id;
  // The line search; the file starts it 30 cm from the farthest tracer instead of 41.8 cm (no
  // push toward the point below the nozzle moves a tracer from farther in the CFD's air), the
  // rest stays the paper's, Sigma0 included.
  EXPECT_EQ(s.controller.search, CemSearch::kLine);
  const CemParameters paper = CemParameters::line_defaults();
  EXPECT_EQ(s.controller.mean0_m, 0.30);
  EXPECT_EQ(s.controller.variance0_m2, paper.variance0_m2);
  EXPECT_EQ(s.controller.samples, paper.samples);
  EXPECT_EQ(s.controller.elite, paper.elite);
  EXPECT_EQ(s.controller.max_iterations, paper.max_iterations);
  EXPECT_EQ(s.controller.converged_variance_m2, paper.converged_variance_m2);
  EXPECT_EQ(s.controller.sweep_clearance_m, 0.10);
  EXPECT_TRUE(s.controller.keep_cheapest);
}

TEST(Scenario, SortingMixesThreeOfEachBetweenTwoZones) {
  const Scenario s = load("sorting");
  expect_common(s, "sorting", 40.0);
  EXPECT_EQ(count_type(s, "tracer"), 3);
  EXPECT_EQ(count_type(s, "cotton"), 3);
  EXPECT_EQ(s.task.kind, TaskKind::kSorting);
  ASSERT_EQ(s.task.zones_by_type.size(), 2u);
  const Zone& tracer = s.task.zones_by_type.at("tracer");
  const Zone& cotton = s.task.zones_by_type.at("cotton");
  EXPECT_DOUBLE_EQ(tracer.radius_m, 0.21 / 2);
  EXPECT_DOUBLE_EQ(cotton.radius_m, 0.21 / 2);
  EXPECT_NEAR((tracer.centre_W - cotton.centre_W).norm(), 1.25, 1e-9);
  // One group, 15-20 cm across, between the zones.
  EXPECT_GT(max_pairwise(s), 0.13);
  EXPECT_LT(max_pairwise(s), 0.21);
  EXPECT_GE(min_pairwise(s), 0.06);
  for (const ObjectSpec& o : s.scene.objects) {
    EXPECT_LT((o.p_W - tracer.centre_W).norm(), 1.25) << o.id;
    EXPECT_LT((o.p_W - cotton.centre_W).norm(), 1.25) << o.id;
  }
  // In stages, tracers first, with the paper's plane search (its Sigma0 too) started from a scan
  // (docs/controller.md).
  EXPECT_TRUE(s.task.stages_auto);
  EXPECT_DOUBLE_EQ(s.task.deferred_weight, 0.1);
  EXPECT_DOUBLE_EQ(s.task.reach_m, 1.0);
  CemParameters expected = CemParameters::plane_defaults();
  expected.scan_step_m = 0.1;
  expected.predict_transition = true;
  expect_same(s.controller, with_shipped_additions(expected));
}

// ---------------------------------------------------------------------------------------------
// Defaults.

constexpr const char* kPathTask = R"(objects:
  - {id: a, type: tracer, x: 0.1, y: 0.2}
task:
  kind: path
  path: [[0.1, 0.2], [0.4, 0.2]]
  time_limit_s: 60
)";

constexpr const char* kSortingTask = R"(objects:
  - {id: a, type: tracer, x: 0.1, y: 0.2}
  - {id: b, type: cotton, x: 0.2, y: 0.2}
task:
  kind: sorting
  zones:
    tracer: {centre: [-0.5, 0], diameter_m: 0.2}
    cotton: {centre: [0.5, 0], diameter_m: 0.2}
  time_limit_s: 60
)";

TEST(ScenarioDefaults, OmittedKeysTakeThePapersValuesForTheTask) {
  const Scenario path = parse_scenario(kPathTask, "dir/my_run.yaml");
  EXPECT_EQ(path.name, "my_run");  // the file's stem
  EXPECT_EQ(path.description, "");
  EXPECT_FALSE(path.task.vertices_as_references);
  EXPECT_DOUBLE_EQ(path.task.reference_spacing_m, 0.10);
  EXPECT_DOUBLE_EQ(path.task.switch_distance_m, 0.04);
  EXPECT_DOUBLE_EQ(path.loop.settle_s, LoopParameters{}.settle_s);
  EXPECT_FALSE(path.scene.objects[0].yaw_rad.has_value());
  expect_same(path.controller, CemParameters::line_defaults());

  const Scenario sorting = parse_scenario(kSortingTask, "s.yaml");
  expect_same(sorting.controller, CemParameters::plane_defaults());
  EXPECT_TRUE(sorting.task.stages_auto);
  EXPECT_TRUE(sorting.task.stages.empty());
  EXPECT_DOUBLE_EQ(sorting.task.deferred_weight, 0.1);
  EXPECT_DOUBLE_EQ(sorting.task.reach_m, 1.0);
}

// task.stages: auto | none | a list of types, each with a zone, once.
TEST(ScenarioDefaults, SortingStagesAreAutoNoneOrAList) {
  auto with = [](const std::string& line) {
    std::string text = kSortingTask;
    const std::string key = "  time_limit_s: 60\n";
    text.replace(text.find(key), key.size(), line + "\n" + key);
    return parse_scenario(text, "s.yaml");
  };
  const Scenario none = with("  stages: none");
  EXPECT_FALSE(none.task.stages_auto);
  EXPECT_TRUE(none.task.stages.empty());
  const Scenario list = with("  stages: [cotton, tracer]");
  EXPECT_FALSE(list.task.stages_auto);
  EXPECT_EQ(list.task.stages, (std::vector<std::string>{"cotton", "tracer"}));
  EXPECT_DOUBLE_EQ(with("  reach_m: 0.8").task.reach_m, 0.8);
  EXPECT_DOUBLE_EQ(with("  deferred_weight: 0.3").task.deferred_weight, 0.3);
  EXPECT_EQ(with("  stages: auto").task.stages_auto, true);
  const CemParameters scanned =
      parse_scenario(std::string(kSortingTask) + "controller: {scan_step_m: 0.05}\n", "s.yaml")
          .controller;
  EXPECT_DOUBLE_EQ(scanned.scan_step_m, 0.05);
  EXPECT_FALSE(scanned.predict_transition);
  EXPECT_TRUE(parse_scenario(std::string(kSortingTask) + "controller: {predict_transition: true}\n",
                             "s.yaml")
                  .controller.predict_transition);
  EXPECT_DOUBLE_EQ(scanned.sweep_clearance_m, 0.0);
  EXPECT_FALSE(scanned.keep_cheapest);
  EXPECT_TRUE(
      parse_scenario(std::string(kPathTask) + "controller: {keep_cheapest: true}\n", "s.yaml")
          .controller.keep_cheapest);
  EXPECT_DOUBLE_EQ(
      parse_scenario(std::string(kPathTask) + "controller: {sweep_clearance_m: 0.15}\n", "s.yaml")
          .controller.sweep_clearance_m,
      0.15);
}

TEST(ScenarioDefaults, KeysOverrideTheDefaultsOfTheSearchInForce) {
  // Sorting with one key changed: the rest stays the plane search's.
  CemParameters expected = CemParameters::plane_defaults();
  expected.samples = 60;
  expect_same(parse_scenario(std::string(kSortingTask) + "controller: {samples: 60}\n", "s.yaml")
                  .controller,
              expected);
  // A path task asking for the plane search gets the plane search's defaults.
  expect_same(parse_scenario(std::string(kPathTask) + "controller:\n  search: plane\n", "p.yaml")
                  .controller,
              CemParameters::plane_defaults());
  // Degrees at the edge, radians inside; an explicit `closed: false` changes nothing.
  const Scenario s = parse_scenario(
      "objects: [{id: a, type: tracer, x: 0, y: 0.3, yaw_deg: 90}]\n"
      "task: {kind: path, path: [[0, 0.3], [0.3, 0.3]], closed: false, time_limit_s: 5}\n"
      "loop: {settle_s: 0, latency_s: 0.25}\n",
      "p.yaml");
  ASSERT_TRUE(s.scene.objects[0].yaw_rad.has_value());
  EXPECT_NEAR(*s.scene.objects[0].yaw_rad, M_PI / 2, 1e-12);
  EXPECT_EQ(s.task.path_W.size(), 2u);
  EXPECT_DOUBLE_EQ(s.loop.settle_s, 0.0);
  EXPECT_DOUBLE_EQ(s.loop.latency_s, 0.25);
}

// ---------------------------------------------------------------------------------------------
// Errors: one InputError whose message is "<source>:<line>: <key path>: ..." (plus `fragment`).

std::string error_of(const std::string& yaml) {
  try {
    parse_scenario(yaml, "scenes/x.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

void expect_error(const std::string& yaml, int line, const std::string& key,
                  const std::string& fragment) {
  const std::string message = error_of(yaml);
  std::string head = "scenes/x.yaml:";
  head += std::to_string(line);
  head += ": ";
  head += key;
  head += ": ";
  EXPECT_EQ(message.rfind(head, 0), 0u) << "expected '" << head << "...', got: " << message;
  EXPECT_NE(message.find(fragment), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

// kPathTask with line `line` (1-based) replaced.
std::string path_task_with(int line, const std::string& replacement) {
  std::string text = kPathTask;
  size_t begin = 0;
  for (int i = 1; i < line; ++i) begin = text.find('\n', begin) + 1;
  const size_t end = text.find('\n', begin);
  return text.substr(0, begin) + replacement + text.substr(end);
}

TEST(ScenarioErrors, WrongTypeNamesKeyLineAndValue) {
  EXPECT_EQ(error_of(R"(objects: [{id: a, type: tracer, x: 0.3, y: 0.3}]
task:
  kind: aggregation
  time_limit_s: 10
  zone:
    centre: [0, 0]
    diameter_m: abc
)"),
            "scenes/x.yaml:7: task.zone.diameter_m: expected a positive number, got 'abc'");
  expect_error(path_task_with(2, "  - {id: a, type: tracer, x: [1], y: 0.2}"), 2, "objects[0].x",
               "got a list");
  expect_error(path_task_with(5, "  path: [[0.1, 0.2], 0.4]"), 5, "task.path[1]",
               "expected a point [x, y] in m");
  expect_error(path_task_with(6, "  time_limit_s: '60'"), 6, "task.time_limit_s",
               "got '60'");  // a quoted string is not a number
  expect_error(std::string(kPathTask) + "controller: {samples: 2.5}\n", 7, "controller.samples",
               "expected an integer");
  expect_error(std::string(kPathTask) + "task2: 1\n", 7, "task2", "unknown key");
  // Not a mapping at the top: no key path to name.
  EXPECT_EQ(error_of("- 1\n- 2\n"), "scenes/x.yaml:1: expected a mapping, got a list");
}

TEST(ScenarioErrors, UnknownKeysAreRejectedWhereTheyStand) {
  expect_error(path_task_with(2, "  - {id: a, type: tracer, x: 0.1, y: 0.2, z: 0}"), 2,
               "objects[0].z", "unknown key; expected one of id, type, x, y, yaw_deg");
  expect_error(path_task_with(4, "  kind: path\n  spacing: 0.1"), 5, "task.spacing", "unknown key");
  // A key of another task kind means nothing here.
  expect_error(path_task_with(4, "  kind: path\n  zone: {centre: [0, 0], diameter_m: 0.3}"), 5,
               "task.zone", "not used by a path task");
  expect_error(std::string(kSortingTask) + "controller:\n  smaples: 10\n", 11, "controller.smaples",
               "unknown key");
}

TEST(ScenarioErrors, MissingRequiredFieldsNameTheMapping) {
  expect_error(path_task_with(2, "  - {id: a, type: tracer, x: 0.1}"), 2, "objects[0].y",
               "missing required key");
  expect_error(path_task_with(6, "  spacing_m: 0.1"), 3, "task.time_limit_s",
               "missing required key");
  expect_error("name: x\n", 1, "objects", "missing required key");
  // A sorting task needs a zone for every type among its objects.
  std::string no_cotton_zone = kSortingTask;
  no_cotton_zone.erase(no_cotton_zone.find("    cotton:"),
                       std::string("    cotton: {centre: [0.5, 0], diameter_m: 0.2}\n").size());
  expect_error(no_cotton_zone, 6, "task.zones.cotton", "need a zone");
}

TEST(ScenarioErrors, DuplicatesAreNamed) {
  expect_error(path_task_with(2,
                              "  - {id: a, type: tracer, x: 0.1, y: 0.2}\n"
                              "  - {id: a, type: tracer, x: 0.5, y: 0.2}"),
               3, "objects[1].id", "duplicate object id 'a' (also objects[0], line 2)");
  expect_error(path_task_with(6, "  time_limit_s: 60\n  time_limit_s: 70"), 7, "task.time_limit_s",
               "duplicate key");
}

TEST(ScenarioErrors, UnknownObjectTypeListsTheKnownOnes) {
  expect_error(path_task_with(2, "  - {id: a, type: pebble, x: 0.1, y: 0.2}"), 2, "objects[0].type",
               "expected tracer | cotton, got 'pebble'");
  expect_error(path_task_with(4, "  kind: herding"), 4, "task.kind",
               "expected path | aggregation | sorting, got 'herding'");
}

TEST(ScenarioErrors, NonFiniteNumbersAreRejected) {
  expect_error(path_task_with(2, "  - {id: a, type: tracer, x: .nan, y: 0.2}"), 2, "objects[0].x",
               "expected a finite number, got '.nan'");
  expect_error(path_task_with(6, "  time_limit_s: .inf"), 6, "task.time_limit_s",
               "expected a finite number, got '.inf'");
  expect_error(path_task_with(5, "  path: [[0.1, 0.2], [1e999, 0.2]]"), 5, "task.path[1][0]",
               "expected a finite number, got '1e999'");
}

TEST(ScenarioErrors, OutOfRangeValuesSayTheRange) {
  expect_error(path_task_with(2, "  - {id: a, type: tracer, x: 2.5, y: 0.2}"), 2, "objects[0].x",
               "inside the camera's view");
  expect_error(path_task_with(6, "  time_limit_s: -3"), 6, "task.time_limit_s", "got '-3'");
  expect_error(path_task_with(5, "  path: [[0.1, 0.2], [0.1, 0.2]]"), 5, "task.path[1]",
               "repeats the previous point");
  expect_error(path_task_with(5, "  path: [[0.1, 0.2]]"), 5, "task.path", "at least 2 points");
  expect_error(std::string(kSortingTask) + "controller: {samples: 5}\n", 10, "controller",
               "elite (10) must not exceed samples (5)");
  expect_error(std::string(kPathTask) + "controller: {samples: 20, elite: 21}\n", 7,
               "controller.elite", "expected an integer in [1, 20]");
  expect_error(std::string(kPathTask) + "loop: {settle_s: -1}\n", 7, "loop.settle_s", "got '-1'");
  expect_error(std::string(kPathTask) + "loop: {latency_s: 11}\n", 7, "loop.latency_s", "got '11'");
  expect_error(std::string(kPathTask) + "loop: {lag_s: 1}\n", 7, "loop.lag_s",
               "unknown key; expected one of settle_s, latency_s");
  // Two footprints that overlap at the start.
  expect_error(path_task_with(2,
                              "  - {id: a, type: tracer, x: 0.1, y: 0.2}\n"
                              "  - {id: b, type: cotton, x: 0.13, y: 0.2}"),
               3, "objects[1]", "overlaps objects[0] (id 'a')");
}

// Sorting in stages and the scan: wrong values name their key (kSortingTask's line 9 is its
// time limit; the new line goes before it).
TEST(ScenarioErrors, SortingStagesAndScanNameTheKey) {
  auto sorting_with = [](const std::string& line) {
    std::string text = kSortingTask;
    const std::string key = "  time_limit_s: 60\n";
    text.replace(text.find(key), key.size(), line + "\n" + key);
    return text;
  };
  expect_error(sorting_with("  stages: [tracer, glass]"), 9, "task.stages[1]",
               "expected tracer | cotton, got 'glass'");
  expect_error(sorting_with("  stages: [tracer, tracer]"), 9, "task.stages[1]",
               "names tracer a second time");
  expect_error(sorting_with("  stages: first"), 9, "task.stages", "expected auto | none");
  expect_error(sorting_with("  deferred_weight: 0"), 9, "task.deferred_weight",
               "expected a number in (0, 1]");
  expect_error(sorting_with("  reach_m: -1"), 9, "task.reach_m", "got '-1'");
  expect_error(path_task_with(4, "  kind: path\n  reach_m: 1.0"), 5, "task.reach_m",
               "not used by a path task");
  expect_error(std::string(kPathTask) + "controller: {scan_step_m: 0.005}\n", 7,
               "controller.scan_step_m", "at least 0.01 m");
  expect_error(std::string(kSortingTask) + "controller: {scan_step_m: 0.001}\n", 10,
               "controller.scan_step_m", "at least 0.01 m");
  expect_error(std::string(kSortingTask) + "controller: {predict_transition: maybe}\n", 10,
               "controller.predict_transition", "true");
  expect_error(std::string(kPathTask) + "controller: {sweep_clearance_m: -0.1}\n", 7,
               "controller.sweep_clearance_m", "0");
  expect_error(std::string(kPathTask) + "controller: {keep_cheapest: 1.5}\n", 7,
               "controller.keep_cheapest", "true");
}

TEST(ScenarioErrors, SyntaxErrorsAndUnreadableFilesAreOneLine) {
  const std::string message = error_of("objects: [\n  {id: a\n");
  EXPECT_EQ(message.rfind("scenes/x.yaml:", 0), 0u) << message;
  EXPECT_NE(message.find("YAML syntax error"), std::string::npos) << message;
  EXPECT_NE(error_of("").find("the file is empty"), std::string::npos);
  try {
    read_scenario("/nonexistent/scenario.yaml");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/scenario.yaml: cannot read the scenario file");
  }
}

}  // namespace
}  // namespace airtwin
