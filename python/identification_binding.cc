// Identification from Python (section IV): a speed series as arrays in, the identified model out,
// the same model and model.json as `airtwin identify --series` on the same numbers.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "models/identification.h"
#include "models/identified_model.h"
#include "models/sindy.h"
#include "models/speed_series.h"
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
}

}  // namespace airtwin::python
