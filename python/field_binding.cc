// The air on the floor from Python: the analytical field (eqs. 1-3) and the jet's CFD, N x 2
// points in, N x 2 velocities out; the nozzle's aim (eqs. 1-2 and their inverse).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "common/errors.h"
#include "common/units.h"
#include "models/air_field.h"
#include "models/cfd_field.h"
#include "models/field_model_file.h"
#include "models/nozzle_geometry.h"
#include "python/arrays.h"
#include "python/bindings.h"

namespace py = pybind11;

namespace airtwin::python {
namespace {

using Point = std::pair<double, double>;

NozzleOrientation orientation_deg(double pan_deg, double tilt_deg) {
  return {deg_to_rad(pan_deg), deg_to_rad(tilt_deg)};
}

// The array the velocities of n points go to: `out` when given (N x 2, C-contiguous float64,
// writeable: written in place), else a new one.
py::array_t<double> output_for(py::ssize_t n, const std::optional<py::array>& out) {
  if (!out) return py::array_t<double>({n, py::ssize_t{2}});
  const bool usable = py::isinstance<py::array_t<double>>(*out) && out->ndim() == 2 &&
                      out->shape(0) == n && out->shape(1) == 2 &&
                      (out->flags() & py::array::c_style) && out->writeable();
  if (!usable) {
    throw InputError("out: expected a writeable C-contiguous float64 array of shape (" +
                     std::to_string(n) + ", 2), got shape " + shape_text(*out));
  }
  return py::reinterpret_borrow<py::array_t<double>>(*out);
}

// The model's velocities at the rows of `points`: the batch evaluation (the one `airtwin field`
// uses) reads the input array and writes the output array in place.
py::array_t<double> model_velocity(const AirFieldModel& model, double pan_deg, double tilt_deg,
                                   const DoubleArray& points, const std::optional<py::array>& o) {
  const py::ssize_t n = rows_of(points, 2, "points");
  py::array_t<double> out = output_for(n, o);
  Eigen::Map<Eigen::Matrix2Xd> v_W(out.mutable_data(), 2, n);
  const auto p_W = as_columns(points);
  {
    py::gil_scoped_release release;
    model.at(orientation_deg(pan_deg, tilt_deg)).velocities(p_W, v_W);
  }
  return out;
}

// The CFD's horizontal mean velocities at the rows of `points`, height z_m above the floor.
py::array_t<double> cfd_velocity(const CfdField& cfd, double pan_deg, double tilt_deg,
                                 const DoubleArray& points, double height_m) {
  const py::ssize_t n = rows_of(points, 2, "points");
  py::array_t<double> out({n, py::ssize_t{2}});
  Eigen::Map<Eigen::Matrix2Xd> v_W(out.mutable_data(), 2, n);
  const auto p_W = as_columns(points);
  {
    py::gil_scoped_release release;
    const CfdOrientedField field = cfd.at(orientation_deg(pan_deg, tilt_deg));
    for (py::ssize_t i = 0; i < n; ++i) v_W.col(i) = field.at(p_W.col(i), height_m).u_W;
  }
  return out;
}

}  // namespace

void bind_field(py::module_& m) {
  py::class_<AirFieldModel>(m, "Field",
                            "The analytical air field of section III (eqs. 1-3): the rig's "
                            "geometry and eq. (3)'s coefficient table. Immutable.")
      .def_static("default", &AirFieldModel::fitted_to_cfd,
                  "The default field model, as the CLI's: eqs. (2)-(3) fitted to the jet's CFD "
                  "(models/data/cfd_fitted_field_model.json).")
      .def_static("constructed", &AirFieldModel::with_constructed_table,
                  "The paper's geometry with the table constructed from the wall-jet literature "
                  "(models/data/constructed_field_table.csv, `airtwin maketable`).")
      .def_static("from_file", &read_air_field_model, py::arg("path"),
                  "A table CSV (tilt_deg,alpha_deg,b1,b2,b3) or a field-model JSON, as "
                  "`airtwin field --table` reads. ValueError naming the file, line and column.")
      .def("velocity", &model_velocity, py::arg("pan_deg"), py::arg("tilt_deg"), py::arg("points"),
           py::arg("out") = py::none(),
           "Air velocity (m/s, N x 2) at floor points (m, N x 2) for the nozzle at pan_deg, "
           "tilt_deg (degrees), into `out` when given (an N x 2 float64 C-contiguous array, "
           "returned). ValueError for a tilt outside [0, 64.4) deg or a wrong shape.")
      .def(
          "stagnation_point",
          [](const AirFieldModel& model, double pan_deg, double tilt_deg) {
            const Eigen::Vector2d s =
                model.at(orientation_deg(pan_deg, tilt_deg)).stagnation_point();
            return Point{s.x(), s.y()};
          },
          py::arg("pan_deg"), py::arg("tilt_deg"),
          "The stagnation point s (m) of this model's geometry (eqs. 1-2), as (x, y).");

  // Held by shared_ptr: twins and runs share one copy of the cases (TwinParameters::cfd_air).
  py::class_<CfdField, std::shared_ptr<CfdField>>(
      m, "CfdField",
      "The jet's air from the CFD cases in data/cfd/ (docs/cfd.md), interpolated "
      "between tilts. Immutable.")
      .def_static(
          "read_dir",
          [](const std::string& dir, int mesh_level, double inlet_diameter_m) {
            py::gil_scoped_release release;
            return CfdField::read_dir(dir, mesh_level, inlet_diameter_m);
          },
          py::arg("dir") = std::string(AIRTWIN_CFD_DIR), py::arg("mesh_level") = 1,
          py::arg("inlet_diameter_m") = 0.02,
          "Every case of the folder at that mesh level and inlet diameter (m), the held-out "
          "tilt left out; default: the shipped data/cfd.")
      .def_property_readonly("min_tilt_deg",
                             [](const CfdField& c) { return rad_to_deg(c.min_tilt_rad()); })
      .def_property_readonly("max_tilt_deg",
                             [](const CfdField& c) { return rad_to_deg(c.max_tilt_rad()); })
      .def("velocity", &cfd_velocity, py::arg("pan_deg"), py::arg("tilt_deg"), py::arg("points"),
           py::arg("height_m") = 0.015,
           "Horizontal mean air velocity (m/s, N x 2) at floor points (m, N x 2), height_m above "
           "the floor. ValueError for a tilt outside the cases' range.")
      .def(
          "stagnation_point",
          [](const CfdField& cfd, double pan_deg, double tilt_deg) {
            const Eigen::Vector2d s = cfd.stagnation_point(orientation_deg(pan_deg, tilt_deg));
            return Point{s.x(), s.y()};
          },
          py::arg("pan_deg"), py::arg("tilt_deg"), "The CFD's stagnation point (m), as (x, y).");

  m.def(
      "aim",
      [](double x_m, double y_m, double max_tilt_deg, double pan_hint_deg,
         const std::optional<AirFieldModel>& field) {
        NozzleGeometry g = (field ? *field : AirFieldModel::fitted_to_cfd()).geometry();
        g.tilt_max_rad = deg_to_rad(max_tilt_deg);
        g.validate();
        const AimResult r = aim_at_stagnation(g, {x_m, y_m}, deg_to_rad(pan_hint_deg));
        if (!r.reachable()) throw InputError("unreachable: " + r.unreachable_reason);
        return Point{rad_to_deg(r.orientation->pan_rad), rad_to_deg(r.orientation->tilt_rad)};
      },
      py::arg("x_m"), py::arg("y_m"), py::arg("max_tilt_deg") = 60.0, py::arg("pan_hint_deg") = 0.0,
      py::arg("field") = py::none(),
      "The nozzle (pan_deg, tilt_deg) whose stagnation point is (x_m, y_m) (the inverse of eqs. "
      "1-2 with `field`'s a1, a2, default Field.default()'s; `airtwin aim`). ValueError "
      "'unreachable: ...' otherwise.");
  m.def(
      "stagnation_point",
      [](double pan_deg, double tilt_deg, const std::optional<AirFieldModel>& field) {
        const NozzleGeometry g = (field ? *field : AirFieldModel::fitted_to_cfd()).geometry();
        const Eigen::Vector2d s = stagnation_point(g, orientation_deg(pan_deg, tilt_deg));
        return Point{s.x(), s.y()};
      },
      py::arg("pan_deg"), py::arg("tilt_deg"), py::arg("field") = py::none(),
      "eqs. (1)-(2) with `field`'s a1, a2 (default Field.default()'s): the stagnation point (m) "
      "as (x, y).");
}

}  // namespace airtwin::python
