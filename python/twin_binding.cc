// The twin from Python: a scenario's objects in the MuJoCo twin, the nozzle commanded in degrees,
// the objects' states as numpy arrays and the top camera's frames as H x W x 3 uint8 (RGB).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>
#include <vector>

#include "common/units.h"
#include "models/air_field.h"
#include "models/cfd_field.h"
#include "python/bindings.h"
#include "python/twin_setup.h"
#include "renders/frame_renderer.h"
#include "scenes/scenario.h"
#include "sim/scene_spec.h"
#include "sim/twin.h"

namespace py = pybind11;

namespace airtwin::python {
namespace {

using Angles = std::pair<double, double>;

Angles degrees(const NozzleOrientation& o) {
  return {rad_to_deg(o.pan_rad), rad_to_deg(o.tilt_rad)};
}

// A twin of a scenario's objects, built as `airtwin run` and `airtwin render` build theirs: the
// default field model, the analytical air or the CFD's (`--air cfd`), the servos at rest at the
// initial orientation and the jet running (settled) or off. reset() builds it again, so it starts
// over to the last bit.
class PyTwin {
 public:
  PyTwin(const std::string& scenario_path, uint64_t seed, double pan_deg, double tilt_deg,
         bool jet_on, const TwinSetup& setup, AirFieldModel field)
      : scenario_(read_scenario(scenario_path)),
        field_(std::move(field)),
        seed_(seed),
        jet_on_(jet_on),
        base_(twin_parameters(setup, scenario_)),
        twin_(build(pan_deg, tilt_deg)) {}

  void reset() {
    renderer_.reset();
    twin_ = build(rad_to_deg(params_.initial_orientation.pan_rad),
                  rad_to_deg(params_.initial_orientation.tilt_rad));
  }

  Twin& twin() { return twin_; }
  const Scenario& scenario() const { return scenario_; }

  // N x 4: x, y (m), vx, vy (m/s) of every object (a copy: the twin computes them on request).
  py::array_t<double> states() const {
    const std::vector<ObjectMotion> motion = twin_.object_states();
    py::array_t<double> out({static_cast<py::ssize_t>(motion.size()), py::ssize_t{4}});
    double* row = out.mutable_data();
    for (const ObjectMotion& m : motion) {
      *row++ = m.p_W.x();
      *row++ = m.p_W.y();
      *row++ = m.v_W.x();
      *row++ = m.v_W.y();
    }
    return out;
  }

  // N x 7: each object's root body as MuJoCo has it after the last step: its origin x, y, z (m,
  // world frame: z above the floor; a tracer's origin is the centre of its flat face) and its
  // orientation quaternion w, x, y, z (xpos, xquat).
  py::array_t<double> poses() const {
    const mjData* d = twin_.data();
    const size_t n = twin_.object_count();
    py::array_t<double> out({static_cast<py::ssize_t>(n), py::ssize_t{7}});
    double* row = out.mutable_data();
    for (size_t i = 0; i < n; ++i) {
      const int b = twin_.object(i).root_body;
      for (int k = 0; k < 3; ++k) *row++ = d->xpos[3 * b + k];
      for (int k = 0; k < 4; ++k) *row++ = d->xquat[4 * b + k];
    }
    return out;
  }

  // The top camera's frame of the current state, RGB (the renderer's BGR converted into the
  // returned array: one pass, no other copy). The renderer is made at the first call, on the
  // calling thread, which its OpenGL context belongs to.
  py::array_t<std::uint8_t> render(int64_t frame_index) {
    if (!renderer_) renderer_ = std::make_unique<FrameRenderer>(twin_.model());
    return rgb_frame(*renderer_, twin_.data(), frame_index, frame_);
  }

 private:
  Twin build(double pan_deg, double tilt_deg) {
    params_ = base_;
    params_.initial_orientation = {deg_to_rad(pan_deg), deg_to_rad(tilt_deg)};
    params_.jet_on_at_start = jet_on_;
    Twin twin(scenario_.scene, params_, field_, seed_);
    if (jet_on_) twin.settle_jet();
    return twin;
  }

  Scenario scenario_;
  AirFieldModel field_;
  uint64_t seed_;
  bool jet_on_;
  TwinParameters base_;  // the set-up's, before the start orientation
  TwinParameters params_;
  Twin twin_;
  std::unique_ptr<FrameRenderer> renderer_;
  cv::Mat frame_;
};

}  // namespace

py::array_t<std::uint8_t> rgb_frame(FrameRenderer& renderer, const mjData* data,
                                    int64_t frame_index, cv::Mat& bgr) {
  py::array_t<std::uint8_t> out(
      {py::ssize_t{renderer.height_px()}, py::ssize_t{renderer.width_px()}, py::ssize_t{3}});
  cv::Mat rgb(renderer.height_px(), renderer.width_px(), CV_8UC3, out.mutable_data());
  py::gil_scoped_release release;
  renderer.render_into(data, frame_index, bgr);
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return out;
}

void bind_twin(py::module_& m) {
  py::class_<Scenario>(m, "Scenario", "A scenario file (scenes/*.yaml, docs/scenario_schema.md).")
      .def_static("load", &read_scenario, py::arg("path"),
                  "Reads and checks a scenario; ValueError naming the file, line and key.")
      .def_readonly("name", &Scenario::name)
      .def_readonly("description", &Scenario::description)
      .def_property_readonly("ids",
                             [](const Scenario& s) {
                               std::vector<std::string> ids;
                               for (const ObjectSpec& o : s.scene.objects) ids.push_back(o.id);
                               return ids;
                             })
      .def_property_readonly("types",
                             [](const Scenario& s) {
                               std::vector<std::string> types;
                               for (const ObjectSpec& o : s.scene.objects) types.push_back(o.type);
                               return types;
                             })
      .def_property_readonly(
          "positions",
          [](const Scenario& s) {
            py::array_t<double> out(
                {static_cast<py::ssize_t>(s.scene.objects.size()), py::ssize_t{2}});
            double* row = out.mutable_data();
            for (const ObjectSpec& o : s.scene.objects) {
              *row++ = o.p_W.x();
              *row++ = o.p_W.y();
            }
            return out;
          },
          "N x 2: the objects' start positions (m).")
      .def_property_readonly("time_limit_s", [](const Scenario& s) { return s.task.time_limit_s; });

  py::class_<PyTwin>(m, "Twin",
                     "The MuJoCo twin of a scenario's objects (docs/twin.md), with the analytical "
                     "air of a field model (default Field.default()), as `airtwin run` builds it.")
      .def(py::init([](const std::string& scenario_path, uint64_t seed, double pan_deg,
                       double tilt_deg, bool jet_on, std::shared_ptr<const CfdField> cfd,
                       const std::string& air, const std::string& drag,
                       const std::vector<std::string>& object_physics,
                       const std::vector<std::string>& effects, const std::string& mjcf,
                       std::optional<bool> air_formation, double air_formation_time_scale,
                       const std::string& integrator, double air_front_co_flow,
                       double air_front_counter_flow, std::optional<bool> air_turbulence_swept,
                       const std::optional<AirFieldModel>& field) {
             const TwinSetup setup{air,
                                   std::move(cfd),
                                   drag,
                                   object_physics,
                                   effects,
                                   mjcf,
                                   air_formation,
                                   air_formation_time_scale,
                                   integrator,
                                   air_front_co_flow,
                                   air_front_counter_flow,
                                   air_turbulence_swept};
             return std::make_unique<PyTwin>(scenario_path, seed, pan_deg, tilt_deg, jet_on, setup,
                                             field ? *field : AirFieldModel::fitted_to_cfd());
           }),
           py::arg("scenario_path"), py::arg("seed"), py::arg("pan_deg") = 0.0,
           py::arg("tilt_deg") = 0.0, py::arg("jet_on") = true, py::arg("cfd") = nullptr,
           py::arg("air") = "cfd", py::arg("drag") = "physical",
           py::arg("object_physics") = std::vector<std::string>{},
           py::arg("effects") = std::vector<std::string>{}, py::arg("mjcf") = "",
           py::arg("air_formation") = py::none(),
           py::arg("air_formation_time_scale") = AirTransportParameters{}.formation_time_scale,
           py::arg("integrator") = "euler",
           py::arg("air_front_co_flow") = AirTransportParameters{}.front_co_flow,
           py::arg("air_front_counter_flow") = AirTransportParameters{}.front_counter_flow,
           py::arg("air_turbulence_swept") = py::none(), py::arg("field") = py::none(),
           "The scenario's objects, seeded with `seed`; the servos at rest at (pan_deg, tilt_deg) "
           "and the jet running (settled) unless jet_on is False. The twin's set-up, as the CLI's "
           "flags, whose defaults it shares (the physical twin): air 'cfd' (the jet's CFD: `cfd`, "
           "a CfdField, or the shipped cases) or 'model' (the analytical field); drag 'physical' "
           "or 'eq8'; object_physics ['TYPE:key=value,...']; effects "
           "['NAME:key=value,...']; mjcf, a user's MJCF scene; air_formation, the wall jet's "
           "formation in the CFD's air (docs/twin.md): None on where the cases have it, True "
           "asks for it (--air-formation), False switches it off (--no-air-formation); "
           "air_formation_time_scale its times' factor (--air-formation-time-scale); integrator "
           "'euler' or 'implicit' (--integrator); air_front_co_flow and air_front_counter_flow, "
           "the new wall jet's front carried by the old air (--air-front-co-flow, "
           "--air-front-counter-flow; both 0: the front of still air); air_turbulence_swept, "
           "the eddies swept past the objects in the CFD's air: None on, True asks for them "
           "(--air-turbulence-swept), False the Lagrangian time alone (--no-air-turbulence-swept); "
           "field, the analytical air "
           "(a Field, as --table; default Field.default()).")
      .def("reset", &PyTwin::reset, "Builds the twin again: the same start, to the last bit.")
      .def(
          "command",
          [](PyTwin& t, double pan_deg, double tilt_deg) {
            t.twin().command_nozzle({deg_to_rad(pan_deg), deg_to_rad(tilt_deg)});
          },
          py::arg("pan_deg"), py::arg("tilt_deg"),
          "New nozzle target (deg); the servos move toward it as time advances.")
      .def(
          "set_jet", [](PyTwin& t, bool on) { t.twin().set_jet(on); }, py::arg("on"))
      .def(
          "advance_to",
          [](PyTwin& t, double t_s) {
            py::gil_scoped_release release;
            t.twin().advance_to(t_s);
          },
          py::arg("t_s"), "Steps until time_s reaches t_s (to the nearest whole step).")
      .def(
          "step",
          [](PyTwin& t, double pan_deg, double tilt_deg, double duration_s) {
            t.twin().command_nozzle({deg_to_rad(pan_deg), deg_to_rad(tilt_deg)});
            {
              py::gil_scoped_release release;
              t.twin().advance(duration_s);
            }
            return t.states();
          },
          py::arg("pan_deg"), py::arg("tilt_deg"), py::arg("duration_s") = 0.025,
          "Commands the nozzle (deg), advances duration_s (default one 40 Hz camera frame) and "
          "returns states().")
      .def("states", &PyTwin::states, "N x 4: x, y (m), vx, vy (m/s) of every object.")
      .def("poses", &PyTwin::poses,
           "N x 7: each object's root body in MuJoCo, its origin x, y, z (m; z above the floor, a "
           "tracer's at its flat face) and its orientation quaternion w, x, y, z.")
      .def("render", &PyTwin::render, py::arg("frame_index") = 0,
           "The top camera's view now: H x W x 3 uint8, RGB, row 0 at the top.")
      .def_property_readonly("time_s", [](PyTwin& t) { return t.twin().time(); })
      .def_property_readonly("timestep_s", [](PyTwin& t) { return t.twin().timestep(); })
      .def_property_readonly("ids",
                             [](PyTwin& t) {
                               std::vector<std::string> ids;
                               for (size_t i = 0; i < t.twin().object_count(); ++i) {
                                 ids.push_back(t.twin().object(i).id);
                               }
                               return ids;
                             })
      .def_property_readonly("commanded_deg",
                             [](PyTwin& t) { return degrees(t.twin().commanded_orientation()); })
      .def_property_readonly("actual_deg",
                             [](PyTwin& t) { return degrees(t.twin().actual_orientation()); })
      .def_property_readonly("stagnation_point", [](PyTwin& t) {
        const Eigen::Vector2d s = t.twin().stagnation_point();
        return std::pair<double, double>{s.x(), s.y()};
      });
}

}  // namespace airtwin::python
