// The twin's moving air at fixed floor points from Python (sim/air_probe.h, `airtwin probe`): a
// nozzle program and points as numpy arrays in, record times and velocities out.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/errors.h"
#include "common/units.h"
#include "models/cfd_field.h"
#include "python/arrays.h"
#include "python/bindings.h"
#include "sim/air_probe.h"

namespace py = pybind11;

namespace airtwin::python {
namespace {

std::pair<py::array_t<double>, py::array_t<double>> probe(
    const DoubleArray& program, const DoubleArray& points, std::shared_ptr<const CfdField> cfd,
    std::optional<bool> formation, double formation_time_scale, double end_s, double interval_s,
    double timestep_s, double front_co_flow, double front_counter_flow) {
  const py::ssize_t knots = rows_of(program, 3, "program");
  const py::ssize_t n = rows_of(points, 3, "points");
  if (knots == 0) throw InputError("program: expected at least one row (t_s, pan_deg, tilt_deg)");
  std::vector<ProgramKnot> prog;
  for (py::ssize_t k = 0; k < knots; ++k) {
    prog.push_back(
        {program.at(k, 0), {deg_to_rad(program.at(k, 1)), deg_to_rad(program.at(k, 2))}});
  }
  std::vector<ProbePoint> pts;
  for (py::ssize_t i = 0; i < n; ++i) {
    pts.push_back({{points.at(i, 0), points.at(i, 1)}, points.at(i, 2)});
  }
  AirTransportParameters params;
  params.formation = formation.value_or(true);
  if (!params.formation && formation_time_scale != params.formation_time_scale) {
    throw FieldError("formation_time_scale", "needs the formation (formation not False)");
  }
  params.formation_time_scale = formation_time_scale;
  params.front_co_flow = front_co_flow;
  params.front_counter_flow = front_counter_flow;
  try {
    params.validate();
  } catch (const FieldError& e) {
    // The argument's name, not the library's field (air_transport.front_co_flow -> front_co_flow).
    const std::string& f = e.field();
    throw FieldError(f.substr(f.find('.') + 1), e.detail());
  }
  AirProbeSettings settings;
  settings.end_s = end_s;
  settings.interval_s = interval_s;
  settings.timestep_s = timestep_s;
  if (!cfd) cfd = std::make_shared<const CfdField>(CfdField::read_dir(AIRTWIN_CFD_DIR));
  if (formation.value_or(false) && !cfd->forms_air()) {
    throw FieldError("formation", std::string("the CFD cases lack ") + CfdField::kFormationData);
  }
  AirProbeRecord r;
  {
    py::gil_scoped_release release;
    r = probe_air(*cfd, params, prog, pts, settings);
  }
  const auto records = static_cast<py::ssize_t>(r.t_s.size());
  py::array_t<double> t(records);
  py::array_t<double> u({records, n, py::ssize_t{2}});
  auto tv = t.mutable_unchecked<1>();
  auto uv = u.mutable_unchecked<3>();
  for (py::ssize_t k = 0; k < records; ++k) {
    tv(k) = r.t_s[k];
    for (py::ssize_t i = 0; i < n; ++i) {
      uv(k, i, 0) = r.u_W[k][i].x();
      uv(k, i, 1) = r.u_W[k][i].y();
    }
  }
  return {t, u};
}

}  // namespace

void bind_probe(py::module_& m) {
  m.def("probe_air", &probe, py::arg("program"), py::arg("points"), py::arg("cfd") = nullptr,
        py::arg("formation") = py::none(),
        py::arg("formation_time_scale") = AirTransportParameters{}.formation_time_scale,
        py::arg("end_s") = 1.0, py::arg("interval_s") = 0.01, py::arg("timestep_s") = 0.0025,
        py::arg("front_co_flow") = AirTransportParameters{}.front_co_flow,
        py::arg("front_counter_flow") = AirTransportParameters{}.front_counter_flow,
        "The twin's mean air at fixed floor points while the nozzle follows a program, as "
        "`airtwin probe` (docs/twin.md): program K x 3 rows (t_s, pan_deg, tilt_deg), linear "
        "between them; points N x 3 (x_m, y_m, z_m); cfd a CfdField (default: the shipped "
        "data/cfd); formation, formation_time_scale, front_co_flow and front_counter_flow as "
        "--air-formation / --no-air-formation, --air-formation-time-scale, --air-front-co-flow "
        "and --air-front-counter-flow. Returns (t, u): record times (T,) from 0 to end_s every "
        "interval_s and the "
        "horizontal air (T, N, 2) in m/s. ValueError naming the field for a bad value.");
}

}  // namespace airtwin::python
