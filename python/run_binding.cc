// A scenario's closed-loop run from Python (runs/scenario_run.h): the CEM controller steering the
// twin's objects, as `airtwin run` runs it with its default options; the result as the files
// the CLI writes and the objects' trajectories as arrays.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "common/errors.h"
#include "models/air_field.h"
#include "models/cfd_field.h"
#include "models/nozzle_log.h"
#include "models/trajectory_data.h"
#include "python/bindings.h"
#include "runs/scenario_run.h"
#include "scenes/scenario.h"

namespace py = pybind11;

namespace airtwin::python {
namespace {

// A run's result and the time limit its summary reports.
struct RunResult {
  ScenarioRunResult result;
  double time_limit_s = 0.0;
};

RunResult run(const std::string& scenario_path, uint64_t seed,
              std::shared_ptr<const CfdField> cfd) {
  const Scenario scenario = read_scenario(scenario_path);
  ScenarioRunOptions options;
  options.seed = seed;
  options.twin.cfd_air = std::move(cfd);
  py::gil_scoped_release release;
  return {run_scenario(scenario, AirFieldModel::with_default_table(), options),
          scenario.task.time_limit_s};
}

// K x 3: t (s), x, y (m) of object `id` every camera frame (a copy of the run's log).
py::array_t<double> trajectory(const RunResult& r, const std::string& id) {
  for (const Trajectory& tr : r.result.log.trajectories) {
    if (tr.id != id) continue;
    py::array_t<double> out({static_cast<py::ssize_t>(tr.samples.size()), py::ssize_t{3}});
    double* row = out.mutable_data();
    for (const TrajectorySample& s : tr.samples) {
      *row++ = s.t_s;
      *row++ = s.p_W.x();
      *row++ = s.p_W.y();
    }
    return out;
  }
  throw InputError("run " + r.result.scenario + ": no object '" + id + "'");
}

}  // namespace

void bind_run(py::module_& m) {
  py::class_<RunResult>(m, "RunResult", "A closed-loop run's result (runs/scenario_run.h).")
      .def_property_readonly("scenario", [](const RunResult& r) { return r.result.scenario; })
      .def_property_readonly("seed", [](const RunResult& r) { return r.result.seed; })
      .def_property_readonly("success", [](const RunResult& r) { return r.result.success; })
      .def_property_readonly(
          "completion_time_s", [](const RunResult& r) { return r.result.loop.completion_time_s; },
          "When the task was seen done (s), or None.")
      .def_property_readonly("n_decisions",
                             [](const RunResult& r) { return r.result.loop.decisions.size(); })
      .def("trajectory", &trajectory, py::arg("id"),
           "K x 3: t (s), x, y (m) of the object every camera frame.")
      .def(
          "summary_json",
          [](const RunResult& r) { return run_summary_json(r.result, r.time_limit_s); },
          "summary.json's text, as `airtwin run` writes it.")
      .def(
          "log_csv", [](const RunResult& r) { return trajectory_csv(r.result.log); },
          "log.csv's text: every object every camera frame, with the command in force.")
      .def(
          "nozzle_csv", [](const RunResult& r) { return nozzle_log_csv(r.result.nozzle_log); },
          "nozzle.csv's text: the commands sent to the nozzle.")
      .def(
          "decisions_csv", [](const RunResult& r) { return decisions_csv(r.result); },
          "decisions.csv's text: every decision of the controller.");

  m.def("run_scenario", &run, py::arg("scenario_path"), py::arg("seed"), py::arg("cfd") = nullptr,
        "Runs the scenario in closed loop in the twin (the CEM controller on the twin's truth, the "
        "default field model and object dynamics), as `airtwin run SCENARIO --seed N` does; the "
        "twin's air the CFD's when `cfd` (a CfdField) is given, as `--air cfd`.");
}

}  // namespace airtwin::python
