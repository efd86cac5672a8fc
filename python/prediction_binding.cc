// Batch trajectory prediction from Python (section V-A, eqs. 8-9): M objects under a schedule of
// nozzle orientations, by the controller's fast predictor or the CVODE reference. The results are
// views of the C++ Prediction's memory (read-only numpy arrays that keep it alive), no copies.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstddef>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "common/errors.h"
#include "common/units.h"
#include "models/air_field.h"
#include "models/cvode_predictor.h"
#include "models/fast_predictor.h"
#include "models/object_dynamics.h"
#include "models/trajectory_predictor.h"
#include "python/arrays.h"
#include "python/bindings.h"

namespace py = pybind11;

namespace airtwin::python {
namespace {

// ObjectState as three doubles: x and y (Eigen::Vector2d) then v, at stride sizeof(ObjectState).
void demand_state_layout() {
  const ObjectState s;
  AIRTWIN_DEMAND(reinterpret_cast<const char*>(s.p_W.data() + 1) -
                     reinterpret_cast<const char*>(&s) ==
                 sizeof(double));
  AIRTWIN_DEMAND(reinterpret_cast<const char*>(&s.v) - reinterpret_cast<const char*>(&s) ==
                 2 * sizeof(double));
}

// A read-only view of `states` (the owner `self` keeps them alive) shaped `leading` x 3: x, y, v.
py::array state_view(const py::object& self, const std::vector<ObjectState>& states,
                     std::vector<py::ssize_t> leading) {
  std::vector<py::ssize_t> shape = leading, strides(leading.size());
  py::ssize_t stride = sizeof(ObjectState);
  for (size_t i = leading.size(); i-- > 0;) {
    strides[i] = stride;
    stride *= leading[i];
  }
  shape.push_back(3);
  strides.push_back(sizeof(double));
  const double* data = states.empty() ? nullptr : states.front().p_W.data();
  py::array view(py::dtype::of<double>(), shape, strides, data, self);
  view.attr("setflags")(py::arg("write") = false);
  return view;
}

py::array vector_view(const py::object& self, const std::vector<double>& values) {
  py::array view(py::dtype::of<double>(), {static_cast<py::ssize_t>(values.size())},
                 {static_cast<py::ssize_t>(sizeof(double))}, values.data(), self);
  view.attr("setflags")(py::arg("write") = false);
  return view;
}

// The schedule from pan and tilt (deg; scalars, or vectors with their start times t_start_s).
OrientationSchedule schedule_of(const DoubleArray& pan_deg, const DoubleArray& tilt_deg,
                                const std::optional<DoubleArray>& t_start_s) {
  const py::ssize_t k = t_start_s ? t_start_s->size() : 1;
  if (t_start_s) require_vector(*t_start_s, k, "t_start_s");
  if (pan_deg.size() != k || tilt_deg.size() != k) {
    throw InputError("pan_deg, tilt_deg: expected " + std::to_string(k) +
                     (t_start_s ? " values each (one per t_start_s)" : " value each") + ", got " +
                     std::to_string(pan_deg.size()) + " and " + std::to_string(tilt_deg.size()));
  }
  OrientationSchedule schedule(k);
  for (py::ssize_t i = 0; i < k; ++i) {
    schedule[i].t_start_s = t_start_s ? t_start_s->data()[i] : 0.0;
    schedule[i].orientation = {deg_to_rad(pan_deg.data()[i]), deg_to_rad(tilt_deg.data()[i])};
  }
  return schedule;
}

Prediction predict(const AirFieldModel& model, const DoubleArray& pan_deg,
                   const DoubleArray& tilt_deg, const DoubleArray& positions,
                   const DoubleArray& dynamics, const std::optional<DoubleArray>& speeds,
                   double horizon_s, double sample_rate_hz,
                   const std::optional<DoubleArray>& t_start_s, const std::string& method) {
  // Inputs into the library's structs (a copy of 6 doubles per object).
  const py::ssize_t n = rows_of(positions, 2, "positions");
  if (rows_of(dynamics, 3, "dynamics") != n) {
    throw InputError("dynamics: expected one row (xi1, xi2, xi3) per object, " + std::to_string(n) +
                     " rows, got " + std::to_string(dynamics.shape(0)));
  }
  if (speeds) require_vector(*speeds, n, "speeds");
  std::vector<ObjectState> start(n);
  std::vector<ObjectDynamics> xi(n);
  for (py::ssize_t j = 0; j < n; ++j) {
    start[j].p_W = {positions.data()[2 * j], positions.data()[2 * j + 1]};
    start[j].v = speeds ? speeds->data()[j] : 0.0;
    xi[j] = {dynamics.data()[3 * j], dynamics.data()[3 * j + 1], dynamics.data()[3 * j + 2]};
  }
  const OrientationSchedule schedule = schedule_of(pan_deg, tilt_deg, t_start_s);
  PredictionOptions options;
  options.horizon_s = horizon_s;
  options.sample_rate_hz = sample_rate_hz;
  if (method != "fast" && method != "cvode") {
    throw InputError("method: expected fast or cvode, got '" + method + "'");
  }

  py::gil_scoped_release release;
  if (method == "fast") return FastPredictor().predict(model, schedule, xi, start, options);
  return CvodePredictor().predict(model, schedule, xi, start, options);
}

}  // namespace

void bind_prediction(py::module_& m) {
  demand_state_layout();
  py::class_<Prediction>(m, "Prediction",
                         "Predicted trajectories of N objects. Arrays are read-only views of the "
                         "C++ result (no copies); columns x, y (m) and v (m/s).")
      .def_property_readonly("n_objects", [](const Prediction& p) { return p.n_objects; })
      .def_property_readonly(
          "end",
          [](const py::object& self) {
            const auto& p = self.cast<const Prediction&>();
            return state_view(self, p.end, {static_cast<py::ssize_t>(p.n_objects)});
          },
          "N x 3: x, y (m), v (m/s) at the horizon.")
      .def_property_readonly(
          "rest_since_s",
          [](const py::object& self) {
            return vector_view(self, self.cast<const Prediction&>().rest_since_s);
          },
          "N: time (s) since which each object rests at the horizon (0: never moved), inf when "
          "still moving.")
      .def_property_readonly(
          "sample_times_s",
          [](const py::object& self) {
            return vector_view(self, self.cast<const Prediction&>().sample_times_s);
          },
          "K: the sample times (s); empty without sample_rate_hz.")
      .def_property_readonly(
          "samples",
          [](const py::object& self) {
            const auto& p = self.cast<const Prediction&>();
            return state_view(self, p.samples,
                              {static_cast<py::ssize_t>(p.sample_times_s.size()),
                               static_cast<py::ssize_t>(p.n_objects)});
          },
          "K x N x 3: every object at every sample time.");

  m.def("predict", &predict, py::arg("field"), py::arg("pan_deg"), py::arg("tilt_deg"),
        py::arg("positions"), py::arg("dynamics"), py::arg("speeds") = py::none(),
        py::arg("horizon_s") = 1.5, py::arg("sample_rate_hz") = 0.0,
        py::arg("t_start_s") = py::none(), py::arg("method") = "fast",
        "Predicts N objects (positions N x 2 in m, dynamics N x 3: eq. (8)'s xi1 (1/s), xi2, xi3 "
        "(m/s^2), speeds N in m/s, default 0) over horizon_s under the nozzle at pan_deg, "
        "tilt_deg (scalars; or vectors with their start times t_start_s, the first <= 0). "
        "method: 'fast' (the controller's RK4) or 'cvode' (the reference). Samples every "
        "1/sample_rate_hz s when > 0. ValueError for bad input.");
  m.def(
      "object_dynamics",
      [](const std::string& name) {
        const ObjectDynamics& d = ObjectTypes::defaults().at(name);
        return std::make_tuple(d.xi1, d.xi2, d.xi3);
      },
      py::arg("name"), "eq. (8)'s (xi1, xi2, xi3) of a shipped object type (tracer, cotton).");
}

}  // namespace airtwin::python
