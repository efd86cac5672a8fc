// Identification from Python (section IV): a speed series as arrays in, the identified model out,
// the same model and model.json as `airtwin identify --series` on the same numbers.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "common/errors.h"
#include "common/units.h"
#include "models/air_field.h"
#include "models/identification.h"
#include "models/identified_model.h"
#include "models/sindy.h"
#include "models/speed_series.h"
#include "models/trajectory_data.h"
#include "python/arrays.h"
#include "python/bindings.h"

namespace py = pybind11;

namespace airtwin::python {
namespace {

std::vector<double> values_of(const DoubleArray& a, const std::string& what) {
  require_vector(a, a.size(), what);
  return {a.data(), a.data() + a.size()};
}

IdentifiedModel identify(const DoubleArray& t_s, const DoubleArray& v_mps,
                         const DoubleArray& vair_mps, const std::string& object,
                         const std::string& method, const std::optional<std::string>& terms,
                         std::uint64_t seed) {
  // The columns are copied into the library's series (three vectors of N doubles).
  SpeedSeries series = make_speed_series(values_of(t_s, "t_s"), values_of(v_mps, "v_mps"),
                                         values_of(vair_mps, "vair_mps"), "speed series");
  IdentificationOptions options;
  options.sindy.method = parse_sindy_method(method);
  if (terms) options.sindy.terms = parse_sindy_terms(*terms);
  options.sindy.seed = seed;
  py::gil_scoped_release release;
  return identify_series(series, object, options);
}

// One trajectory of the Python list: a dict of t_s (K), positions (K x 2, m) and commands_deg
// (K x 2: the pan and tilt in force at each sample, deg), optionally id and group; copied into
// the library's samples with the checks the trajectory CSV's reader makes.
Trajectory trajectory_of(const py::dict& d, size_t index, const std::string& object) {
  const std::string what = "trajectories[" + std::to_string(index) + "]";
  for (const char* key : {"t_s", "positions", "commands_deg"}) {
    if (!d.contains(key)) throw InputError(what + ": no '" + key + "'");
  }
  const DoubleArray t = py::cast<DoubleArray>(d["t_s"]);
  const DoubleArray p = py::cast<DoubleArray>(d["positions"]);
  const DoubleArray c = py::cast<DoubleArray>(d["commands_deg"]);
  const py::ssize_t k = t.size();
  require_vector(t, k, what + ".t_s");
  if (k == 0) throw InputError(what + ".t_s: no samples");
  if (rows_of(p, 2, what + ".positions") != k || rows_of(c, 2, what + ".commands_deg") != k) {
    throw InputError(what + ": t_s, positions and commands_deg need one row per sample (" +
                     std::to_string(k) + ")");
  }
  Trajectory tr;
  tr.id = d.contains("id") ? py::str(d["id"]).cast<std::string>() : std::to_string(index);
  tr.group = d.contains("group") ? py::str(d["group"]).cast<std::string>() : "";
  tr.object = object;
  for (py::ssize_t j = 0; j < k; ++j) {
    TrajectorySample s;
    s.t_s = t.data()[j];
    s.p_W = {p.data()[2 * j], p.data()[2 * j + 1]};
    s.nozzle = {deg_to_rad(c.data()[2 * j]), deg_to_rad(c.data()[2 * j + 1])};
    if (!(std::isfinite(s.t_s) && s.p_W.allFinite() && std::isfinite(s.nozzle.pan_rad) &&
          std::isfinite(s.nozzle.tilt_rad))) {
      throw InputError(what + ": sample " + std::to_string(j) + " is not finite");
    }
    if (j > 0 && !(s.t_s > tr.samples.back().t_s)) {
      throw InputError(what + ".t_s: time must increase strictly (sample " + std::to_string(j) +
                       ")");
    }
    tr.samples.push_back(s);
  }
  return tr;
}

IdentifiedModel identify_tracks(const py::list& trajectories, const std::string& object,
                                const AirFieldModel* field, const std::string& method,
                                const std::optional<std::string>& terms, std::uint64_t seed) {
  if (!default_object_types().count(object)) {
    throw InputError("object: expected tracer or cotton, got '" + object + "'");
  }
  TrajectorySet set;
  set.has_group = false;
  for (size_t i = 0; i < trajectories.size(); ++i) {
    set.trajectories.push_back(trajectory_of(py::cast<py::dict>(trajectories[i]), i, object));
    set.has_group = set.has_group || !set.trajectories.back().group.empty();
  }
  IdentificationOptions options;
  options.sindy.method = parse_sindy_method(method);
  if (terms) options.sindy.terms = parse_sindy_terms(*terms);
  options.sindy.seed = seed;
  const AirFieldModel model = field ? *field : AirFieldModel::fitted_to_cfd();
  py::gil_scoped_release release;
  return identify_trajectories(set, object, model, options);
}

}  // namespace

void bind_identification(py::module_& m) {
  py::class_<IdentifiedModel>(m, "IdentifiedModel",
                              "An identified object model (section IV; model.json, "
                              "docs/data_formats.md).")
      .def_readonly("object", &IdentifiedModel::object)
      .def_readonly("method", &IdentifiedModel::method)
      .def_property_readonly_static(
          "terms",
          [](const py::object&) {
            return std::vector<std::string>(kTermNames.begin(), kTermNames.end());
          },
          "The ten library terms, in the order of coefficients.")
      .def_property_readonly(
          "coefficients",
          [](const IdentifiedModel& model) {
            return std::vector<double>(model.coefficients.data(),
                                       model.coefficients.data() + kSindyTerms);
          },
          "dv/dt (m/s^2) per term, continuous time.")
      .def_readonly("r2", &IdentifiedModel::r2)
      .def_readonly("n_pairs", &IdentifiedModel::n_pairs)
      .def_property_readonly(
          "eq8",
          [](const IdentifiedModel& model) -> std::optional<std::tuple<double, double, double>> {
            if (!model.is_eq8()) return std::nullopt;
            const ObjectDynamics d = model.eq8();
            return std::make_tuple(d.xi1, d.xi2, d.xi3);
          },
          "eq. (8)'s (xi1 (1/s), xi2, xi3 (m/s^2)) when only its terms are active, else None.")
      .def("to_json", &identified_model_json, "The model.json text.");

  m.def("identify_series", &identify, py::arg("t_s"), py::arg("v_mps"), py::arg("vair_mps"),
        py::arg("object") = "", py::arg("method") = "robust-esindy", py::arg("terms") = py::none(),
        py::arg("seed") = 1,
        "Identifies eq. (6)'s model from a speed series: times (s, uniformly sampled), the "
        "object's speed and the air speed at it (m/s), as `airtwin identify --series` with the "
        "same method, terms (e.g. '1,v,vair') and seed. ValueError for bad input.");

  m.def("identify_trajectories", &identify_tracks, py::arg("trajectories"), py::arg("object"),
        py::arg("field") = nullptr, py::arg("method") = "robust-esindy",
        py::arg("terms") = py::none(), py::arg("seed") = 1,
        "Identifies eq. (6)'s model from trajectories of one object type, as `airtwin identify "
        "DATA.csv --object T`: a list of dicts, each t_s (K, s), positions (K x 2, m) and "
        "commands_deg (K x 2: the nozzle's pan and tilt in force, deg), optionally id and "
        "group; the air speed from `field` (a Field; default Field.default(), fitted to the CFD). "
        "ValueError "
        "for bad input.");
}

}  // namespace airtwin::python
