// The feasible manipulation region from Python (runs/manipulation_region.h, `airtwin region`):
// the line search's pushes over a grid of the floor, judged by the controller's model and, on
// request, in the twin; every push as arrays, the counts as region.json's text.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/errors.h"
#include "python/bindings.h"
#include "python/twin_setup.h"
#include "runs/manipulation_region.h"
#include "runs/scenario_run.h"

namespace py = pybind11;

namespace airtwin::python {
namespace {

struct PyRegion {
  RegionOptions options;
  std::vector<RegionPush> pushes;
  RegionSummary summary;
  std::optional<TrajectorySet> twin_records;  ///< with the twin: every push's record
};

PyRegion region(const RegionOptions& options, bool twin, const TwinSetup& setup,
                const ControllerSetup& controller) {
  options.validate();
  // What only the twin uses is refused without it rather than ignored.
  if (!twin && !setup.effects.empty()) throw FieldError("effects", "needs twin=True");
  if (!twin && !setup.object_physics.empty()) {
    throw FieldError("object_physics", "needs twin=True");
  }
  const AirFieldModel field = controller_field_model(controller);
  ScenarioRunOptions run;
  plan_with_model_files(controller_models(controller, setup), field, &run);
  PyRegion r;
  r.options = options;
  const TwinParameters twin_params = twin ? twin_parameters(setup, Scenario{}) : TwinParameters{};
  {
    py::gil_scoped_release release;
    r.pushes = model_region(options, field, run);
    if (twin) {
      r.twin_records.emplace();
      run_region_in_twin(&r.pushes, options, twin_params, field, {}, &*r.twin_records);
    }
  }
  r.summary = summarize_region(r.pushes, options);
  return r;
}

// P x 2 of a point per push; NaN where `get` gives none.
py::array_t<double> points(const PyRegion& r,
                           std::optional<Eigen::Vector2d> (*get)(const RegionPush&)) {
  py::array_t<double> a({static_cast<py::ssize_t>(r.pushes.size()), py::ssize_t{2}});
  double* out = a.mutable_data();
  for (size_t i = 0; i < r.pushes.size(); ++i) {
    const std::optional<Eigen::Vector2d> p = get(r.pushes[i]);
    out[2 * i] = p ? p->x() : std::numeric_limits<double>::quiet_NaN();
    out[2 * i + 1] = p ? p->y() : std::numeric_limits<double>::quiet_NaN();
  }
  return a;
}

// A value per push; NaN where `get` gives none.
py::array_t<double> values(const PyRegion& r, std::optional<double> (*get)(const RegionPush&)) {
  py::array_t<double> a(static_cast<py::ssize_t>(r.pushes.size()));
  double* out = a.mutable_data();
  for (size_t i = 0; i < r.pushes.size(); ++i) {
    out[i] = get(r.pushes[i]).value_or(std::numeric_limits<double>::quiet_NaN());
  }
  return a;
}

std::optional<double> along(const RegionPush& p, const std::optional<Eigen::Vector2d>& end) {
  if (!end) return std::nullopt;
  return travel_along(p, *end);
}

}  // namespace

void bind_region(py::module_& m) {
  py::class_<PyRegion>(m, "Region",
                       "The line search's pushes over a grid and who they moved "
                       "(runs/manipulation_region.h); arrays have a row per push, points x "
                       "fastest, each point's directions counter-clockwise from +x.")
      .def_property_readonly(
          "points",
          [](const PyRegion& r) {
            return points(
                r, [](const RegionPush& p) -> std::optional<Eigen::Vector2d> { return p.p_W; });
          },
          "P x 2: the object at rest (m).")
      .def_property_readonly(
          "directions",
          [](const PyRegion& r) {
            return points(r, [](const RegionPush& p) -> std::optional<Eigen::Vector2d> {
              return p.direction_W;
            });
          },
          "P x 2: the push's direction (unit).")
      .def_property_readonly(
          "stagnation_points",
          [](const PyRegion& r) {
            return points(
                r, [](const RegionPush& p) -> std::optional<Eigen::Vector2d> { return p.s_W; });
          },
          "P x 2: s, a distance D behind the object (m).")
      .def_property_readonly(
          "classes",
          [](const PyRegion& r) {
            std::vector<std::string> out;
            for (const RegionPush& p : r.pushes) {
              out.push_back(kPushClasses[static_cast<size_t>(p.push_class)].name);
            }
            return out;
          },
          "Per push: 'away', 'across' or 'toward' the point below the nozzle.")
      .def_property_readonly(
          "reachable",
          [](const PyRegion& r) {
            py::array_t<bool> a(static_cast<py::ssize_t>(r.pushes.size()));
            for (size_t i = 0; i < r.pushes.size(); ++i) {
              a.mutable_data()[i] = r.pushes[i].reachable();
            }
            return a;
          },
          "Per push: whether the nozzle can put s there.")
      .def_property_readonly(
          "model_end",
          [](const PyRegion& r) {
            return points(r, [](const RegionPush& p) { return p.model_end_W; });
          },
          "P x 2: the model's predicted end (m; NaN where s is out of reach).")
      .def_property_readonly(
          "twin_end",
          [](const PyRegion& r) {
            return points(r, [](const RegionPush& p) { return p.twin_end_W; });
          },
          "P x 2: where the twin's object was after Delta T (m; NaN without the twin or where s "
          "is out of reach).")
      .def_property_readonly(
          "model_along_m",
          [](const PyRegion& r) {
            return values(r, [](const RegionPush& p) { return along(p, p.model_end_W); });
          },
          "Per push: the model's travel along the direction (m; NaN where it has no end).")
      .def_property_readonly(
          "twin_along_m",
          [](const PyRegion& r) {
            return values(r, [](const RegionPush& p) { return along(p, p.twin_end_W); });
          },
          "Per push: the twin's travel along the direction (m; NaN where it has no end).")
      .def(
          "summary_json", [](const PyRegion& r) { return region_json(r.summary, r.options); },
          "region.json's text: the counts per class, the region's points, the agreement.")
      .def(
          "csv", [](const PyRegion& r) { return region_csv(r.pushes); }, "region.csv's text.")
      .def(
          "trajectories_csv",
          [](const PyRegion& r) {
            if (!r.twin_records)
              throw InputError("trajectories_csv: the region was computed without twin=True");
            return trajectory_csv(*r.twin_records);
          },
          "The twin's record of every reachable push as a trajectory CSV (`--trajectories-out`'s "
          "text): 40 Hz from the release, id the push's row.")
      .def(
          "write_png",
          [](const PyRegion& r, const std::string& path) {
            write_region_png(r.pushes, r.summary, r.options, path);
          },
          py::arg("path"), "Writes region.png: a map per judge.");

  m.def(
      "manipulation_region",
      [](const std::string& object, double distance_m, double extent_m, double step_m,
         int directions, double horizon_s, double min_travel_m, bool twin, uint64_t seed,
         double settle_s, int threads, std::shared_ptr<const CfdField> cfd, const std::string& air,
         const std::string& drag, const std::vector<std::string>& object_physics,
         const std::vector<std::string>& effects, const std::string& table,
         const std::vector<std::string>& models, std::optional<bool> air_turbulence_swept) {
        RegionOptions o;
        o.object = object;
        o.distance_m = distance_m;
        o.extent_m = extent_m;
        o.step_m = step_m;
        o.directions = directions;
        o.horizon_s = horizon_s;
        o.min_travel_m = min_travel_m;
        o.seed = seed;
        o.settle_s = settle_s;
        o.threads = threads;
        TwinSetup setup;
        setup.air = air;
        setup.cfd = std::move(cfd);
        setup.drag = drag;
        setup.object_physics = object_physics;
        setup.effects = effects;
        setup.air_turbulence_swept = air_turbulence_swept;
        return region(o, twin, setup, ControllerSetup{table, models});
      },
      py::arg("object") = "tracer", py::arg("distance_m") = RegionOptions{}.distance_m,
      py::arg("extent_m") = RegionOptions{}.extent_m, py::arg("step_m") = RegionOptions{}.step_m,
      py::arg("directions") = RegionOptions{}.directions,
      py::arg("horizon_s") = RegionOptions{}.horizon_s,
      py::arg("min_travel_m") = RegionOptions{}.min_travel_m, py::arg("twin") = false,
      py::arg("seed") = RegionOptions{}.seed, py::arg("settle_s") = RegionOptions{}.settle_s,
      py::arg("threads") = 0, py::arg("cfd") = nullptr, py::arg("air") = "cfd",
      py::arg("drag") = "physical", py::arg("object_physics") = std::vector<std::string>{},
      py::arg("effects") = std::vector<std::string>{}, py::arg("table") = "",
      py::arg("models") = std::vector<std::string>{}, py::arg("air_turbulence_swept") = py::none(),
      "The feasible manipulation region, as `airtwin region` computes it: on a grid of +-extent_m "
      "at step_m, for each of `directions` directions, the line search's push (s distance_m "
      "behind an object at rest, held horizon_s) and whether it moved the object min_travel_m "
      "along the direction, by the model the controller plans with (`table`, `models`: as "
      "run_scenario's) and, with twin=True, in the twin (its set-up as run_scenario's: cfd, air, "
      "drag, object_physics, effects, air_turbulence_swept; each trial seeded by `seed`). "
      "Returns a Region. ValueError naming the field (region.step_m, ...) for a bad value.");
}

}  // namespace airtwin::python
