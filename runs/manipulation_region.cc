#include "runs/manipulation_region.h"

#include <cmath>
#include <cstdio>
#include <mutex>
#include <thread>

#include <nlohmann/json.hpp>

#include "common/errors.h"
#include "common/parallel_for.h"
#include "common/random_stream.h"
#include "common/units.h"
#include "plots/region_plot.h"
#include "sim/collection.h"

namespace airtwin {
namespace {

// Grid points from the origin to the grid's edge along an axis.
int half_count(const RegionOptions& o) {
  return static_cast<int>(std::floor(o.extent_m / o.step_m + 1e-9));
}

// The verdict of a judge's end: the object went at least min_travel along the push.
bool moved(const RegionPush& push, const Eigen::Vector2d& end_W, const RegionOptions& o) {
  return travel_along(push, end_W) >= o.min_travel_m;
}

}  // namespace

void RegionOptions::validate() const {
  if (object != "tracer" && object != "cotton") {
    throw FieldError("region.object", "expected tracer or cotton, got '" + object + "'");
  }
  if (!(extent_m > 0.0 && extent_m <= 1.9)) {
    throw FieldError("region.extent_m",
                     "expected a half-width in (0, 1.9] m (the twin's floor spans +-2 m)");
  }
  if (!(step_m >= 0.01 && step_m <= extent_m)) {
    throw FieldError("region.step_m", "expected a spacing in [0.01 m, extent]");
  }
  if (directions < 1 || directions > 64) {
    throw FieldError("region.directions", "expected a count in [1, 64]");
  }
  // Nearer than delta_min the controller's eq. (10) penalises the push: it never makes it.
  if (!(distance_m > CemParameters{}.min_distance_m && distance_m <= 2.0)) {
    throw FieldError("region.distance_m",
                     "expected a distance in (0.1, 2] m (nearer, eq. (10)'s delta_min forbids the "
                     "push)");
  }
  if (!(horizon_s > 0.0 && horizon_s <= 60.0)) {
    throw FieldError("region.horizon_s", "expected seconds in (0, 60]");
  }
  if (!(min_travel_m > 0.0 && min_travel_m <= 1.0)) {
    throw FieldError("region.min_travel_m", "expected a distance in (0, 1] m");
  }
  if (!(settle_s >= 0.0 && settle_s <= 60.0)) {
    throw FieldError("region.settle_s", "expected seconds in [0, 60]");
  }
  if (threads < 0 || threads > 256) {
    throw FieldError("region.threads", "expected a count in [0, 256]");
  }
  const double side = 2.0 * half_count(*this) + 1.0;
  if (side * side * directions > kMaxRegionPushes) {
    throw FieldError("region.step_m",
                     "the grid and directions make " +
                         std::to_string(static_cast<long long>(side * side * directions)) +
                         " pushes, more than " + std::to_string(kMaxRegionPushes) +
                         ": a larger step, a smaller extent or fewer directions");
  }
}

PushClass classify_push(const Eigen::Vector2d& p_W, const Eigen::Vector2d& d_W) {
  const double r = p_W.norm();
  if (!(r > 1e-9)) return PushClass::kAcross;
  const double c = p_W.dot(d_W) / r;
  const double edge = std::sqrt(0.5);  // cos 45 deg
  if (c >= edge) return PushClass::kAway;
  if (c <= -edge) return PushClass::kToward;
  return PushClass::kAcross;
}

double travel_along(const RegionPush& push, const Eigen::Vector2d& end_W) {
  return (end_W - push.p_W).dot(push.direction_W);
}

std::vector<RegionPush> plan_region(const RegionOptions& options, const NozzleGeometry& geometry) {
  options.validate();
  const int n_side = half_count(options);
  std::vector<RegionPush> pushes;
  for (int iy = -n_side; iy <= n_side; ++iy) {
    for (int ix = -n_side; ix <= n_side; ++ix) {
      const Eigen::Vector2d p(ix * options.step_m, iy * options.step_m);
      for (int k = 0; k < options.directions; ++k) {
        const double a = 2.0 * kPi * k / options.directions;
        RegionPush push;
        push.index = static_cast<int>(pushes.size());
        push.p_W = p;
        push.direction_W = Eigen::Vector2d(std::cos(a), std::sin(a));
        push.s_W = p - options.distance_m * push.direction_W;
        push.push_class = classify_push(p, push.direction_W);
        // At the origin any pan puts s there: the direction's own pan, as the line search's.
        push.orientation = aim_at_stagnation(geometry, push.s_W, a).orientation;
        pushes.push_back(push);
      }
    }
  }
  return pushes;
}

void predict_region(std::vector<RegionPush>* pushes, const CemPlanner& planner,
                    const ObjectDynamics& xi, const std::string& type) {
  std::vector<Eigen::Vector2d> end;
  for (RegionPush& push : *pushes) {
    if (!push.reachable()) continue;
    const Eigen::Vector2d position = push.p_W;
    const Eigen::Vector2d velocity = Eigen::Vector2d::Zero();
    const Eigen::Vector2d reference = push.p_W + push.direction_W;
    PlanningProblem problem;
    problem.positions_W = std::span<const Eigen::Vector2d>(&position, 1);
    problem.velocities_W = std::span<const Eigen::Vector2d>(&velocity, 1);
    problem.dynamics = std::span<const ObjectDynamics>(&xi, 1);
    problem.types = std::span<const std::string>(&type, 1);  // its own effects, when per type
    problem.references_W = std::span<const Eigen::Vector2d>(&reference, 1);
    problem.pan_hint_rad = push.orientation->pan_rad;
    planner.cost(problem, push.s_W, &end);
    push.model_end_W = end.front();
  }
}

std::vector<RegionPush> model_region(const RegionOptions& options, const AirFieldModel& field,
                                     const ScenarioRunOptions& run) {
  const auto xi = run.dynamics.find(options.object);
  if (xi == run.dynamics.end()) {
    throw InputError("region: the controller has no model for object type '" + options.object +
                     "'");
  }
  const AirFieldModel& planning = run.planning_field ? *run.planning_field : field;
  CemParameters params;
  params.horizon_s = options.horizon_s;
  const CemPlanner planner(planning, params, {}, run.planning_extensions);
  std::vector<RegionPush> pushes = plan_region(options, planning.geometry());
  predict_region(&pushes, planner, xi->second, options.object);
  return pushes;
}

void run_region_in_twin(std::vector<RegionPush>* pushes, const RegionOptions& options,
                        const TwinParameters& params, const AirFieldModel& field,
                        const std::function<void(int, int)>& progress,
                        TrajectorySet* trajectories) {
  options.validate();
  CollectionOptions collection;
  collection.object = options.object;
  collection.protocol = CollectionProtocol::kPlaced;
  collection.wait_s = options.settle_s;
  collection.record_s = options.horizon_s;
  collection.twin = params;
  collection.validate();
  std::vector<RegionPush*> reachable;
  for (RegionPush& push : *pushes) {
    if (push.reachable()) reachable.push_back(&push);
  }
  const int n = static_cast<int>(reachable.size());
  const int threads = options.threads == 0 ? static_cast<int>(std::thread::hardware_concurrency())
                                           : options.threads;
  std::mutex mutex;  // guards done and the progress callback
  int done = 0;
  std::vector<Trajectory> records(trajectories != nullptr ? reachable.size() : 0);
  parallel_for(reachable.size(), threads, [&](size_t i) {
    RegionPush& push = *reachable[i];
    CollectionTrial trial;
    trial.index = push.index;
    trial.target = *push.orientation;
    trial.start_W = push.p_W;
    trial.placed = true;
    RandomStream rs(options.seed, RandomPurpose::kCollection, static_cast<uint64_t>(push.index));
    trial.twin_seed = static_cast<uint64_t>(rs.uniform() * 0x1.0p53);
    Trajectory tr = run_collection_trial(trial, collection, field);
    push.twin_end_W = tr.samples.back().p_W;
    if (trajectories != nullptr) records[i] = std::move(tr);
    const std::lock_guard lock(mutex);
    ++done;
    if (progress) progress(done, n);
  });
  if (trajectories != nullptr) {
    trajectories->trajectories = std::move(records);
    trajectories->has_group = false;
  }
}

namespace {

// One judge's verdicts from the ends `end_of` gives (none: the judge did not see the push).
template <typename EndOf>
RegionJudgement judge(const std::vector<RegionPush>& pushes, const RegionOptions& options,
                      EndOf end_of) {
  RegionJudgement j;
  for (size_t first = 0; first < pushes.size(); first += static_cast<size_t>(options.directions)) {
    bool every = true;
    for (int k = 0; k < options.directions; ++k) {
      const RegionPush& push = pushes[first + static_cast<size_t>(k)];
      const std::optional<Eigen::Vector2d>& end = end_of(push);
      if (!push.reachable() || !end) {
        every = false;
        continue;
      }
      const bool went = moved(push, *end, options);
      RegionTally& c = j.by_class[static_cast<size_t>(push.push_class)];
      ++j.all.of;
      ++c.of;
      if (went) {
        ++j.all.moved;
        ++c.moved;
      }
      every = every && went;
    }
    if (every) ++j.region_points;
  }
  return j;
}

nlohmann::ordered_json judgement_json(const RegionJudgement& j, const RegionOptions& options) {
  nlohmann::ordered_json out;
  out["moved"] = j.all.moved;
  out["of"] = j.all.of;
  nlohmann::ordered_json by_class;
  for (const PushClassInfo& c : kPushClasses) {
    const RegionTally& t = j.by_class[static_cast<size_t>(c.id)];
    by_class[c.name] = {{"moved", t.moved}, {"of", t.of}};
  }
  out["by_class"] = by_class;
  out["region_points"] = j.region_points;
  out["region_area_m2"] = j.region_points * options.step_m * options.step_m;
  return out;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6f", v);
  return buf;
}

}  // namespace

RegionSummary summarize_region(const std::vector<RegionPush>& pushes,
                               const RegionOptions& options) {
  options.validate();
  if (pushes.size() % static_cast<size_t>(options.directions) != 0) {
    throw InputError("region: " + std::to_string(pushes.size()) +
                     " pushes are not whole points of " + std::to_string(options.directions) +
                     " directions");
  }
  RegionSummary s;
  s.pushes = static_cast<int>(pushes.size());
  s.points = s.pushes / options.directions;
  bool any_model = false, any_twin = false;
  for (const RegionPush& push : pushes) {
    if (!push.reachable()) continue;
    ++s.reachable;
    any_model = any_model || push.model_end_W.has_value();
    any_twin = any_twin || push.twin_end_W.has_value();
    if (push.model_end_W && push.twin_end_W) {
      const bool m = moved(push, *push.model_end_W, options);
      const bool t = moved(push, *push.twin_end_W, options);
      (m ? (t ? s.both : s.model_only) : (t ? s.twin_only : s.neither))++;
    }
  }
  if (any_model) {
    s.model = judge(
        pushes, options,
        [](const RegionPush& p) -> const std::optional<Eigen::Vector2d>& { return p.model_end_W; });
  }
  if (any_twin) {
    s.twin = judge(
        pushes, options,
        [](const RegionPush& p) -> const std::optional<Eigen::Vector2d>& { return p.twin_end_W; });
  }
  return s;
}

std::string region_csv(const std::vector<RegionPush>& pushes) {
  std::string out =
      "x,y,direction_deg,class,s_x,s_y,pan_deg,tilt_deg,reachable,model_end_x,model_end_y,"
      "model_along_m,twin_end_x,twin_end_y,twin_along_m\n";
  // Each cell after the first starts with its comma; an empty optional leaves the cell empty.
  const auto cell = [&out](const std::string& text) {
    out += ',';
    out += text;
  };
  for (const RegionPush& push : pushes) {
    double a = rad_to_deg(std::atan2(push.direction_W.y(), push.direction_W.x()));
    if (a < 0.0) a += 360.0;
    out += number(push.p_W.x());
    cell(number(push.p_W.y()));
    cell(number(a));
    cell(kPushClasses[static_cast<size_t>(push.push_class)].name);
    cell(number(push.s_W.x()));
    cell(number(push.s_W.y()));
    cell(push.reachable() ? number(rad_to_deg(push.orientation->pan_rad)) : "");
    cell(push.reachable() ? number(rad_to_deg(push.orientation->tilt_rad)) : "");
    cell(push.reachable() ? "1" : "0");
    for (const std::optional<Eigen::Vector2d>* end : {&push.model_end_W, &push.twin_end_W}) {
      cell(*end ? number((*end)->x()) : "");
      cell(*end ? number((*end)->y()) : "");
      cell(*end ? number(travel_along(push, **end)) : "");
    }
    out += '\n';
  }
  return out;
}

std::string region_json(const RegionSummary& summary, const RegionOptions& options) {
  nlohmann::ordered_json j;
  j["format"] = "airtwin-region 1";
  j["object"] = options.object;
  j["extent_m"] = options.extent_m;
  j["step_m"] = options.step_m;
  j["directions"] = options.directions;
  j["distance_m"] = options.distance_m;
  j["horizon_s"] = options.horizon_s;
  j["min_travel_m"] = options.min_travel_m;
  j["points"] = summary.points;
  j["pushes"] = summary.pushes;
  j["reachable"] = summary.reachable;
  j["model"] = summary.model ? judgement_json(*summary.model, options) : nlohmann::ordered_json();
  if (summary.twin) {
    j["settle_s"] = options.settle_s;
    j["seed"] = options.seed;
    j["twin"] = judgement_json(*summary.twin, options);
  } else {
    j["twin"] = nullptr;
  }
  if (summary.model && summary.twin) {
    j["agreement"] = {{"both", summary.both},
                      {"model_only", summary.model_only},
                      {"twin_only", summary.twin_only},
                      {"neither", summary.neither}};
  } else {
    j["agreement"] = nullptr;
  }
  return j.dump(1) + "\n";
}

void write_region_png(const std::vector<RegionPush>& pushes, const RegionSummary& summary,
                      const RegionOptions& options, const std::string& path,
                      const Scenario* scenario) {
  plots::RegionPlot plot;
  plot.extent_m = options.extent_m;
  plot.step_m = options.step_m;
  for (const RegionPush& push : pushes) {
    plot.points_W.push_back(push.p_W);
    plot.directions_W.push_back(push.direction_W);
  }
  const auto panel = [&](const char* judge, const RegionJudgement& j,
                         std::optional<Eigen::Vector2d> RegionPush::*end) {
    plots::RegionPanel p;
    char title[160];
    std::snprintf(title, sizeof title, "%s: moved %d/%d; every way at %d/%d points", judge,
                  j.all.moved, j.all.of, j.region_points, summary.points);
    p.title = title;
    for (const RegionPush& push : pushes) {
      const std::optional<Eigen::Vector2d>& e = push.*end;
      p.verdicts.push_back(!push.reachable() || !e    ? plots::PushVerdict::kUnreachable
                           : moved(push, *e, options) ? plots::PushVerdict::kMoved
                                                      : plots::PushVerdict::kStill);
    }
    plot.panels.push_back(p);
  };
  if (summary.model) panel("model", *summary.model, &RegionPush::model_end_W);
  if (summary.twin) panel("twin", *summary.twin, &RegionPush::twin_end_W);
  char line[160];
  std::snprintf(line, sizeof line, "%s at rest, s %.1f cm behind it, held %.2f s;",
                options.object.c_str(), 100.0 * options.distance_m, options.horizon_s);
  plot.caption.push_back(line);
  std::snprintf(line, sizeof line, "moved: %.1f cm or more along the push%s",
                100.0 * options.min_travel_m,
                scenario != nullptr ? "; blue: the scenario's task" : "");
  plot.caption.push_back(line);
  if (scenario != nullptr) {
    const TaskSpec& task = scenario->task;
    if (task.kind == TaskKind::kPath) plot.path_W = task.path_W;
    if (task.kind == TaskKind::kAggregation)
      plot.zones.push_back({task.zone.centre_W, task.zone.radius_m});
    for (const auto& [type, zone] : task.zones_by_type)
      plot.zones.push_back({zone.centre_W, zone.radius_m});
    for (const ObjectSpec& o : scenario->scene.objects) plot.objects_W.push_back(o.p_W);
  }
  plots::write_region_png(plot, path);
}

}  // namespace airtwin
