#include "scenes/scenario.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "common/errors.h"
#include "common/units.h"
#include "sim/scene_builder.h"

namespace airtwin {
namespace {

// One node of the document and the key path that leads to it ("task.zone.diameter_m",
// "objects[3].x"), so that every message can name both the line and the key.
struct Field {
  YAML::Node node;
  std::string path;
  /// Where the key that holds it stands (null for list elements and the root): errors about a
  /// mapping as a whole (a missing key) point there, those about a value at the value.
  YAML::Mark key_mark = YAML::Mark::null_mark();

  YAML::Mark head_mark() const { return key_mark.is_null() ? node.Mark() : key_mark; }
};

std::string kind_of(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map:
      return "a mapping";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Null:
      return "nothing";
    default:
      return "'" + node.Scalar() + "'";
  }
}

std::string number_text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// Every error of the loader goes through here: "<source>:<line>: <key path>: <what>".
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  const std::string& source() const { return source_; }

  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& path,
                         const std::string& what) const {
    std::string message = source_;
    if (!mark.is_null()) message += ":" + std::to_string(mark.line + 1);
    message += ": ";
    if (!path.empty()) message += path + ": ";
    message += what;
    throw InputError(message);
  }
  [[noreturn]] void fail(const Field& f, const std::string& what) const {
    fail(f.node.Mark(), f.path, what);
  }
  [[noreturn]] void expected(const Field& f, const std::string& what) const {
    fail(f, "expected " + what + ", got " + kind_of(f.node));
  }

  // --- scalars ---

  // A plain (unquoted) scalar read as a finite number; `what` describes the expectation.
  double number(const Field& f, const std::string& what = "a number") const {
    if (!f.node.IsScalar() || f.node.Tag() == "!") expected(f, what);
    const std::string& text = f.node.Scalar();
    // YAML's own spellings of the non-finite values, then anything strtod takes whole.
    static const std::set<std::string> kNonFinite = {".nan",  ".NaN",  ".NAN",  ".inf",
                                                     ".Inf",  ".INF",  "+.inf", "+.Inf",
                                                     "+.INF", "-.inf", "-.Inf", "-.INF"};
    if (kNonFinite.count(text)) fail(f, "expected a finite number, got '" + text + "'");
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size()) expected(f, what);
    if (!std::isfinite(v) || errno == ERANGE) {
      fail(f, "expected a finite number, got '" + text + "'");
    }
    return v;
  }
  double positive(const Field& f) const {
    const double v = number(f, "a positive number");
    if (!(v > 0)) expected(f, "a positive number");
    return v;
  }
  double in_range(const Field& f, double lo, double hi, const std::string& unit) const {
    const std::string what =
        "a number in [" + number_text(lo) + ", " + number_text(hi) + "]" + unit;
    const double v = number(f, what);
    if (!(v >= lo && v <= hi)) expected(f, what);
    return v;
  }
  int integer(const Field& f, int lo, int hi) const {
    const std::string what =
        "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    const double v = number(f, what);
    if (!(v == std::floor(v) && v >= lo && v <= hi)) expected(f, what);
    return static_cast<int>(v);
  }
  std::string text(const Field& f) const {
    if (!f.node.IsScalar()) expected(f, "a text");
    return f.node.Scalar();
  }
  std::string choice(const Field& f, std::initializer_list<const char*> choices) const {
    std::string list;
    for (const char* c : choices) list += std::string(list.empty() ? "" : " | ") + c;
    if (!f.node.IsScalar()) expected(f, list);
    for (const char* c : choices) {
      if (f.node.Scalar() == c) return c;
    }
    expected(f, list);
  }
  bool boolean(const Field& f) const { return choice(f, {"true", "false"}) == "true"; }

  // A point [x, y] in metres, within `half_extent_m` of the origin in both axes.
  Eigen::Vector2d point(const Field& f, double half_extent_m) const {
    if (!f.node.IsSequence() || f.node.size() != 2) expected(f, "a point [x, y] in m");
    Eigen::Vector2d p;
    for (int k = 0; k < 2; ++k) {
      p[k] = in_range({f.node[k], f.path + "[" + std::to_string(k) + "]"}, -half_extent_m,
                      half_extent_m, " m");
    }
    return p;
  }

 private:
  std::string source_;
};

// A mapping whose keys are checked once: duplicates and keys outside `allowed` fail at
// construction; get() hands out the fields by name.
class MapFields {
 public:
  MapFields(const Reader& reader, const Field& f, std::initializer_list<const char*> allowed)
      : reader_(reader), field_(f) {
    if (!f.node.IsMap()) reader.expected(f, "a mapping");
    std::set<std::string> allowed_set(allowed.begin(), allowed.end());
    std::string allowed_list;
    for (const char* a : allowed) allowed_list += std::string(allowed_list.empty() ? "" : ", ") + a;
    for (auto it = f.node.begin(); it != f.node.end(); ++it) {
      const Field key{it->first, f.path};
      if (!it->first.IsScalar()) reader.fail(key, "expected a key, got " + kind_of(it->first));
      const std::string name = it->first.Scalar();
      const std::string key_path = join(name);
      if (!allowed_set.count(name)) {
        reader.fail(it->first.Mark(), key_path, "unknown key; expected one of " + allowed_list);
      }
      for (const auto& [seen, node] : entries_) {
        if (seen == name) reader.fail(it->first.Mark(), key_path, "duplicate key");
      }
      entries_.push_back({name, it->second});
      key_marks_.push_back(it->first.Mark());
    }
  }

  bool has(const std::string& key) const { return find(key) >= 0; }

  /// The field `key`, or nullopt when absent.
  std::optional<Field> optional(const std::string& key) const {
    const int i = find(key);
    if (i < 0) return std::nullopt;
    return Field{entries_[i].second, join(key), key_marks_[i]};
  }
  /// The field `key`; absent: an error at the line of the mapping's own key.
  Field required(const std::string& key) const {
    const int i = find(key);
    if (i < 0) reader_.fail(field_.head_mark(), join(key), "missing required key");
    return Field{entries_[i].second, join(key), key_marks_[i]};
  }
  /// Rejects `key` when present: it means nothing in this context (`why`).
  void forbid(const std::string& key, const std::string& why) const {
    const int i = find(key);
    if (i >= 0) reader_.fail(key_marks_[i], join(key), why);
  }

  const Field& field() const { return field_; }

 private:
  int find(const std::string& key) const {
    for (size_t i = 0; i < entries_.size(); ++i) {
      if (entries_[i].first == key) return static_cast<int>(i);
    }
    return -1;
  }
  std::string join(const std::string& key) const {
    if (field_.path.empty()) return key;
    std::string path = field_.path;
    path += ".";
    path += key;
    return path;
  }

  const Reader& reader_;
  Field field_;
  std::vector<std::pair<std::string, YAML::Node>> entries_;
  std::vector<YAML::Mark> key_marks_;
};

std::string element_path(const std::string& path, size_t i) {
  std::string p = path;
  p += "[";
  p += std::to_string(i);
  p += "]";
  return p;
}

// The floor the camera sees (+-1.35 m for the twin): starts, paths and zones must lie in it.
double view_half_extent_m() { return SceneParameters{}.camera_half_view_m; }

// objects: a list of {id, type, x, y, yaw_deg?}; ids unique, types known, footprints apart.
std::vector<ObjectSpec> read_objects(const Reader& r, const Field& f) {
  if (!f.node.IsSequence() || f.node.size() == 0) r.expected(f, "a non-empty list of objects");
  const SceneParameters scene;
  std::vector<ObjectSpec> objects;
  std::vector<YAML::Mark> marks;
  std::vector<double> radius;
  for (size_t i = 0; i < f.node.size(); ++i) {
    const MapFields m(r, {f.node[i], element_path(f.path, i)}, {"id", "type", "x", "y", "yaw_deg"});
    ObjectSpec o;
    const Field id = m.required("id");
    o.id = r.text(id);
    if (o.id.empty()) r.fail(id, "expected a non-empty id");
    for (size_t j = 0; j < objects.size(); ++j) {
      if (objects[j].id == o.id) {
        r.fail(id, "duplicate object id '" + o.id + "' (also objects[" + std::to_string(j) +
                       "], line " + std::to_string(marks[j].line + 1) + ")");
      }
    }
    const Field type = m.required("type");
    o.type = r.choice(type, {"tracer", "cotton"});
    const ObjectType kind = o.type == "tracer" ? ObjectType::kTracer : ObjectType::kCotton;
    const double rad = 0.5 * scene.of(kind).diameter_m *
                       (kind == ObjectType::kCotton ? 1.0 + scene.cotton_irregularity : 1.0);
    const double reach = view_half_extent_m() - rad;
    o.p_W.x() = r.in_range(m.required("x"), -reach, reach, " m (inside the camera's view)");
    o.p_W.y() = r.in_range(m.required("y"), -reach, reach, " m (inside the camera's view)");
    if (auto yaw = m.optional("yaw_deg"))
      o.yaw_rad = deg_to_rad(r.in_range(*yaw, -360, 360, " deg"));
    // Footprints must not overlap: a start inside another object explodes on contact.
    for (size_t j = 0; j < objects.size(); ++j) {
      const double d = (objects[j].p_W - o.p_W).norm();
      if (d < radius[j] + rad) {
        r.fail(m.field().head_mark(), m.field().path,
               "overlaps objects[" + std::to_string(j) + "] (id '" + objects[j].id +
                   "'): centres " + number_text(d) + " m apart, footprints need " +
                   number_text(radius[j] + rad) + " m");
      }
    }
    objects.push_back(o);
    marks.push_back(f.node[i].Mark());
    radius.push_back(rad);
  }
  return objects;
}

// A zone {centre: [x, y], diameter_m}: the paper gives zones by diameter, stored as radius.
Zone read_zone(const Reader& r, const Field& f) {
  const MapFields m(r, f, {"centre", "diameter_m"});
  Zone zone;
  zone.centre_W = r.point(m.required("centre"), view_half_extent_m());
  const Field diameter = m.required("diameter_m");
  const double d = r.positive(diameter);
  if (d > 2.0 * view_half_extent_m()) {
    r.expected(diameter, "a positive number up to " + number_text(2.0 * view_half_extent_m()) +
                             " m (the camera's view)");
  }
  zone.radius_m = 0.5 * d;
  return zone;
}

TaskSpec read_task(const Reader& r, const Field& f, const std::vector<ObjectSpec>& objects) {
  const MapFields m(r, f,
                    {"kind", "path", "closed", "references", "spacing_m", "switch_distance_m",
                     "zone", "zones", "stages", "deferred_weight", "reach_m", "time_limit_s"});
  TaskSpec task;
  const std::string kind = r.choice(m.required("kind"), {"path", "aggregation", "sorting"});
  task.kind = kind == "path"          ? TaskKind::kPath
              : kind == "aggregation" ? TaskKind::kAggregation
                                      : TaskKind::kSorting;
  task.time_limit_s = r.in_range(m.required("time_limit_s"), 1.0, 86400.0, " s");

  // Keys of the other kinds mean nothing here: a misplaced key is an error, not ignored.
  const std::string not_for = "not used by a " + kind + " task";
  if (task.kind != TaskKind::kPath) {
    for (const char* key : {"path", "closed", "references", "spacing_m", "switch_distance_m"}) {
      m.forbid(key, not_for);
    }
  }
  if (task.kind != TaskKind::kAggregation) m.forbid("zone", not_for);
  if (task.kind != TaskKind::kSorting) {
    for (const char* key : {"zones", "stages", "deferred_weight", "reach_m"}) {
      m.forbid(key, not_for);
    }
  }

  switch (task.kind) {
    case TaskKind::kPath: {
      // The polyline, optionally closed back to its first vertex (the square, the octagon).
      const Field path = m.required("path");
      if (!path.node.IsSequence() || path.node.size() < 2) {
        r.expected(path, "a list of at least 2 points [x, y] in m");
      }
      for (size_t i = 0; i < path.node.size(); ++i) {
        const Field vertex{path.node[i], element_path(path.path, i)};
        task.path_W.push_back(r.point(vertex, view_half_extent_m()));
        if (i > 0 && (task.path_W[i] - task.path_W[i - 1]).norm() < 1e-6) {
          r.fail(vertex, "repeats the previous point");
        }
      }
      if (auto closed = m.optional("closed"); closed && r.boolean(*closed)) {
        if ((task.path_W.back() - task.path_W.front()).norm() > 1e-6) {
          task.path_W.push_back(task.path_W.front());
        }
      }
      if (auto refs = m.optional("references")) {
        task.vertices_as_references = r.choice(*refs, {"vertices", "spaced"}) == "vertices";
      }
      if (auto spacing = m.optional("spacing_m")) {
        task.reference_spacing_m = r.in_range(*spacing, 0.01, 2.0, " m");
      }
      if (auto sw = m.optional("switch_distance_m")) {
        task.switch_distance_m = r.in_range(*sw, 0.005, 0.5, " m");
      }
      break;
    }
    case TaskKind::kAggregation:
      task.zone = read_zone(r, m.required("zone"));
      break;
    case TaskKind::kSorting: {
      // One zone per object type; every type among the objects needs its zone.
      const Field zones = m.required("zones");
      const MapFields z(r, zones, {"tracer", "cotton"});
      for (const char* type : {"tracer", "cotton"}) {
        if (auto zone = z.optional(type)) task.zones_by_type[type] = read_zone(r, *zone);
      }
      for (const ObjectSpec& o : objects) {
        if (!task.zones_by_type.count(o.type)) {
          r.fail(zones.head_mark(), zones.path + "." + o.type,
                 "missing required key (objects of type " + o.type + ", e.g. '" + o.id +
                     "', need a zone)");
        }
      }
      // stages: auto (default) | none | [type, ...] (controller/task.h).
      if (auto stages = m.optional("stages")) {
        if (stages->node.IsScalar()) {
          task.stages_auto = r.choice(*stages, {"auto", "none"}) == "auto";
        } else if (stages->node.IsSequence() && stages->node.size() > 0) {
          task.stages_auto = false;
          for (size_t i = 0; i < stages->node.size(); ++i) {
            const Field type{stages->node[i], element_path(stages->path, i)};
            const std::string name = r.choice(type, {"tracer", "cotton"});
            if (!task.zones_by_type.count(name)) r.fail(type, "no zone is given for " + name);
            if (std::find(task.stages.begin(), task.stages.end(), name) != task.stages.end()) {
              r.fail(type, "names " + name + " a second time");
            }
            task.stages.push_back(name);
          }
        } else {
          r.expected(*stages, "auto | none | a list of object types");
        }
      }
      if (auto w = m.optional("deferred_weight")) {
        task.deferred_weight = r.number(*w, "a number in (0, 1]");
        if (!(task.deferred_weight > 0.0 && task.deferred_weight <= 1.0)) {
          r.expected(*w, "a number in (0, 1]");
        }
      }
      if (auto reach = m.optional("reach_m")) task.reach_m = r.in_range(*reach, 0.05, 5.0, " m");
      break;
    }
  }
  return task;
}

// controller: the CEM parameters. Defaults are the paper's for the search in force (line for
// path and aggregation, plane for sorting, or the one `search` names), then each key overrides.
CemParameters read_controller(const Reader& r, const std::optional<Field>& f, TaskKind kind) {
  CemSearch search = kind == TaskKind::kSorting ? CemSearch::kPlane : CemSearch::kLine;
  std::optional<MapFields> m;
  if (f) {
    m.emplace(r, *f,
              std::initializer_list<const char*>{
                  "search", "horizon_s", "penalty", "min_distance_m", "mean0_m", "variance0_m2",
                  "samples", "elite", "max_iterations", "converged_variance_m2", "scan_step_m",
                  "predict_transition", "sweep_clearance_m", "keep_cheapest"});
    if (auto s = m->optional("search")) {
      search = r.choice(*s, {"line", "plane"}) == "line" ? CemSearch::kLine : CemSearch::kPlane;
    }
  }
  CemParameters p =
      search == CemSearch::kLine ? CemParameters::line_defaults() : CemParameters::plane_defaults();
  if (!m) return p;
  if (auto v = m->optional("horizon_s")) p.horizon_s = r.in_range(*v, 0.05, 10.0, " s");
  if (auto v = m->optional("penalty")) p.penalty = r.positive(*v);
  if (auto v = m->optional("min_distance_m")) p.min_distance_m = r.in_range(*v, 0.0, 1.0, " m");
  if (auto v = m->optional("mean0_m")) p.mean0_m = r.in_range(*v, 0.0, 3.0, " m");
  if (auto v = m->optional("variance0_m2")) p.variance0_m2 = r.positive(*v);
  if (auto v = m->optional("samples")) p.samples = r.integer(*v, 2, 100000);
  if (auto v = m->optional("max_iterations")) p.max_iterations = r.integer(*v, 1, 1000);
  if (auto v = m->optional("converged_variance_m2")) p.converged_variance_m2 = r.positive(*v);
  if (auto v = m->optional("scan_step_m")) {
    p.scan_step_m = r.in_range(*v, 0.0, 1.0, " m");
    if (p.scan_step_m > 0.0 && p.scan_step_m < 0.01) {
      r.expected(*v, "0 (no scan) or a pitch of at least 0.01 m");
    }
  }
  if (auto v = m->optional("predict_transition")) p.predict_transition = r.boolean(*v);
  if (auto v = m->optional("sweep_clearance_m")) {
    p.sweep_clearance_m = r.in_range(*v, 0.0, 1.0, " m");
  }
  if (auto v = m->optional("keep_cheapest")) p.keep_cheapest = r.boolean(*v);
  // n* must leave a choice among the n samples.
  if (auto v = m->optional("elite")) p.elite = r.integer(*v, 1, p.samples);
  if (!(p.elite >= 1 && p.elite <= p.samples)) {
    r.fail(m->field().head_mark(), m->field().path,
           "elite (" + std::to_string(p.elite) + ") must not exceed samples (" +
               std::to_string(p.samples) + ")");
  }
  return p;
}

std::string stem_of(const std::string& source) {
  const std::string stem = std::filesystem::path(source).stem().string();
  return stem.empty() ? source : stem;
}

}  // namespace

Scenario parse_scenario(const std::string& yaml_text, const std::string& source) {
  const Reader r(source);
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    r.fail(e.mark, "", "YAML syntax error: " + e.msg);
  }
  if (!root.IsDefined() || root.IsNull()) r.fail(YAML::Mark::null_mark(), "", "the file is empty");

  Scenario s;
  s.source = source;
  try {
    const MapFields top(r, {root, ""},
                        {"name", "description", "objects", "task", "controller", "loop"});
    s.name = stem_of(source);
    if (auto name = top.optional("name")) {
      s.name = r.text(*name);
      if (s.name.empty()) r.fail(*name, "expected a non-empty name");
    }
    if (auto description = top.optional("description")) s.description = r.text(*description);
    s.scene.source = source;
    s.scene.objects = read_objects(r, top.required("objects"));
    s.task = read_task(r, top.required("task"), s.scene.objects);
    s.controller = read_controller(r, top.optional("controller"), s.task.kind);
    if (auto loop = top.optional("loop")) {
      const MapFields l(r, *loop, {"settle_s", "latency_s"});
      if (auto settle = l.optional("settle_s"))
        s.loop.settle_s = r.in_range(*settle, 0.0, 10.0, " s");
      if (auto latency = l.optional("latency_s"))
        s.loop.latency_s = r.in_range(*latency, 0.0, 10.0, " s");
    }
  } catch (const YAML::Exception& e) {
    // yaml-cpp's own complaints while walking the tree (should not happen: every access is
    // checked first), still one line with the place.
    r.fail(e.mark, "", e.msg);
  }

  // The checks of the consumers themselves (they name the source and the field).
  s.task.validate(source);
  s.controller.validate(source);
  validate_scene(s.scene, SceneParameters{});
  return s;
}

Scenario read_scenario(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot read the scenario file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path + ": cannot read the scenario file");
  return parse_scenario(text.str(), path);
}

}  // namespace airtwin
