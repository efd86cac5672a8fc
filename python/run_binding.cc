// A scenario's closed-loop run from Python (runs/scenario_run.h): the CEM controller steering the
// twin's objects, as `airtwin run` runs it with its default options; the result as the files
// the CLI writes and the objects' trajectories as arrays.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/units.h"
#include "models/nozzle_geometry.h"
#include "rigs/vision_perception.h"
#include "vision/calibrated_camera.h"

#include "common/errors.h"
#include "models/air_field.h"
#include "models/cfd_field.h"
#include "models/field_model_file.h"
#include "models/nozzle_log.h"
#include "models/trajectory_data.h"
#include "python/bindings.h"
#include "python/twin_setup.h"
#include "runs/scenario_episode.h"
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

RunResult run(const std::string& scenario_path, uint64_t seed, const TwinSetup& setup,
              const ControllerSetup& controller, const std::string& vary_physics,
              int planner_threads) {
  const Scenario scenario = read_scenario(scenario_path);
  const AirFieldModel field = controller_field_model(controller);
  ScenarioRunOptions options;
  options.seed = seed;
  options.twin = twin_parameters(setup, scenario);
  options.physics_variation = PhysicsVariation::parse(vary_physics, "vary_physics");
  plan_with_model_files(controller_models(controller, setup), field, &options);
  options.planner_threads = planner_threads;
  py::gil_scoped_release release;
  return {run_scenario(scenario, field, options), scenario.task.time_limit_s};
}

// A closed-loop run one turn at a time (runs/scenario_episode.h), the base of airtwin.env: the
// scenario, field and options it refers to are kept with it.
class PyEpisode {
 public:
  PyEpisode(const std::string& scenario_path, uint64_t seed, const TwinSetup& setup,
            const ControllerSetup& controller, bool vision, const std::string& calib,
            const std::string& calib_dir, double vision_rate_hz, double noise_sigma_grey,
            double blur_sigma_px, const std::string& vary_physics, int planner_threads)
      : scenario_(read_scenario(scenario_path)), field_(controller_field_model(controller)) {
    options_.seed = seed;
    options_.planner_threads = planner_threads;
    options_.twin = twin_parameters(setup, scenario_);
    options_.physics_variation = PhysicsVariation::parse(vary_physics, "vary_physics");
    plan_with_model_files(controller_models(controller, setup), field_, &options_);
    py::gil_scoped_release release;
    if (vision) {
      options_.vision.rate_hz = vision_rate_hz;
      options_.vision.noise_sigma_grey = noise_sigma_grey;
      options_.vision.blur_sigma_px = blur_sigma_px;
      if (!calib.empty()) {
        options_.vision_camera = CalibratedCamera::read(calib);
      } else {
        // The twin's camera calibrated as a user calibrates the rig's, as `airtwin run --vision`
        // does without --calib: checkerboard views into calib_dir/calibration,
        // calib_dir/calib.yaml.
        if (calib_dir.empty()) throw FieldError("calib_dir", "vision without calib needs a folder");
        options_.vision_camera = calibrate_twin_camera(
            calib_dir + "/calibration", options_.twin.scene, seed, noise_sigma_grey, blur_sigma_px);
        options_.vision_camera->write(calib_dir + "/calib.yaml");
      }
    } else if (!calib.empty()) {
      throw FieldError("calib", "a camera model needs vision");
    }
    episode_ = std::make_unique<ScenarioEpisode>(scenario_, field_, options_);
  }

  ScenarioEpisode& episode() { return *episode_; }
  const Scenario& scenario() const { return scenario_; }
  const AirFieldModel& field() const { return field_; }
  const TwinParameters& twin() const { return options_.twin; }
  RunResult result() const { return {episode_->result(), scenario_.task.time_limit_s}; }

  // The top camera's frame of the episode's twin now (the renderer made at the first call, on
  // the calling thread, which its OpenGL context belongs to).
  py::array_t<std::uint8_t> render() {
    const Twin& twin = episode_->twin();
    if (!renderer_) renderer_ = std::make_unique<FrameRenderer>(twin.model());
    return rgb_frame(*renderer_, twin.data(), std::llround(twin.time() * 40.0), frame_);
  }

 private:
  Scenario scenario_;
  AirFieldModel field_;
  ScenarioRunOptions options_;
  std::unique_ptr<ScenarioEpisode> episode_;
  std::unique_ptr<FrameRenderer> renderer_;
  cv::Mat frame_;
};

// N x 2 rows of points.
py::array_t<double> rows(const std::vector<Eigen::Vector2d>& points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), py::ssize_t{2}});
  double* row = out.mutable_data();
  for (const Eigen::Vector2d& p : points) {
    *row++ = p.x();
    *row++ = p.y();
  }
  return out;
}

// What the controller knows now (DecisionInputs), as a dict of arrays in id order.
py::dict known(const Controller& controller) {
  const DecisionInputs in = controller.inputs();
  py::dict d;
  d["ids"] = in.ids;
  d["types"] = in.types;
  d["positions"] = rows(in.positions_W);
  d["velocities"] = rows(in.velocities_W);
  d["references"] = rows(in.references_W);
  py::array_t<double> xi({static_cast<py::ssize_t>(in.dynamics.size()), py::ssize_t{3}});
  double* row = xi.mutable_data();
  for (const ObjectDynamics& x : in.dynamics) {
    *row++ = x.xi1;
    *row++ = x.xi2;
    *row++ = x.xi3;
  }
  d["dynamics"] = xi;
  py::array_t<bool> seen(static_cast<py::ssize_t>(in.seen.size()));
  for (size_t j = 0; j < in.seen.size(); ++j) seen.mutable_data()[j] = in.seen[j] != 0;
  d["seen"] = seen;
  d["weights"] = in.shaping.weights;
  d["reach_m"] = in.shaping.reach_m;
  return d;
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
      .def_property_readonly(
          "lost_every_object", [](const RunResult& r) { return r.result.loop.lost_every_object; },
          "The run stopped early, failed, because the perception had lost every object.")
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

  m.def(
      "run_scenario",
      [](const std::string& scenario_path, uint64_t seed, std::shared_ptr<const CfdField> cfd,
         const std::string& air, const std::string& drag,
         const std::vector<std::string>& object_physics, const std::vector<std::string>& effects,
         const std::string& mjcf, const std::string& table, const std::vector<std::string>& models,
         std::optional<bool> air_formation, double air_formation_time_scale,
         const std::string& integrator, double air_front_co_flow, double air_front_counter_flow,
         std::optional<bool> air_turbulence_swept, const std::string& vary_physics,
         int planner_threads) {
        return run(scenario_path, seed,
                   TwinSetup{air, std::move(cfd), drag, object_physics, effects, mjcf,
                             air_formation, air_formation_time_scale, integrator, air_front_co_flow,
                             air_front_counter_flow, air_turbulence_swept},
                   ControllerSetup{table, models}, vary_physics, planner_threads);
      },
      py::arg("scenario_path"), py::arg("seed"), py::arg("cfd") = nullptr, py::arg("air") = "cfd",
      py::arg("drag") = "physical", py::arg("object_physics") = std::vector<std::string>{},
      py::arg("effects") = std::vector<std::string>{}, py::arg("mjcf") = "", py::arg("table") = "",
      py::arg("models") = std::vector<std::string>{}, py::arg("air_formation") = py::none(),
      py::arg("air_formation_time_scale") = AirTransportParameters{}.formation_time_scale,
      py::arg("integrator") = "euler",
      py::arg("air_front_co_flow") = AirTransportParameters{}.front_co_flow,
      py::arg("air_front_counter_flow") = AirTransportParameters{}.front_counter_flow,
      py::arg("air_turbulence_swept") = py::none(), py::arg("vary_physics") = "none",
      py::arg("planner_threads") = 1,
      "Runs the scenario in closed loop in the twin (the CEM controller on the twin's truth), as "
      "`airtwin run SCENARIO --seed N` does; the twin's set-up as Twin's (air, cfd, drag, "
      "object_physics, effects, mjcf, air_formation, air_formation_time_scale, integrator: the "
      "flags --air, --cfd, --drag, --object-physics, --effect, --mjcf, --air-formation (None: "
      "the default, True: --air-formation, False: --no-air-formation), "
      "--air-formation-time-scale, --integrator; air_front_co_flow, air_front_counter_flow, "
      "air_turbulence_swept: --air-front-co-flow, --air-front-counter-flow, "
      "--air-turbulence-swept (None: the default, on in CFD air; False: "
      "--no-air-turbulence-swept)); the controller's field model `table` "
      "(a table CSV or field-model "
      "JSON, as --table; default the one fitted to the CFD) and `models` (model.json or "
      "extended_model.json files, as --model; default, as the CLI's: in the physical twin the "
      "models fitted to it, models/data/twin/extended_model.json or, with "
      "air_turbulence_swept False, models/data/twin_lagrangian/, else the paper's eq. (8)); "
      "vary_physics: each object its own physics drawn from the seed, 'documented' or a spread "
      "in (0, 0.5], as --vary-physics (the drawn values in summary_json's object_physics); "
      "planner_threads: threads that predict each decision's candidates, as --planner-threads "
      "(the same run for any number).");

  py::class_<DecisionRecord>(m, "Decision", "One decision of the shipped controller.")
      .def_property_readonly(
          "stagnation_point",
          [](const DecisionRecord& d) {
            return std::pair{d.plan.stagnation_W.x(), d.plan.stagnation_W.y()};
          },
          "s* (m).")
      .def_property_readonly(
          "pan_deg", [](const DecisionRecord& d) { return rad_to_deg(d.plan.orientation.pan_rad); })
      .def_property_readonly(
          "tilt_deg",
          [](const DecisionRecord& d) { return rad_to_deg(d.plan.orientation.tilt_rad); })
      .def_property_readonly("cost", [](const DecisionRecord& d) { return d.plan.cost; });

  py::class_<PyEpisode>(m, "Episode",
                        "A closed-loop run one turn at a time (runs/scenario_episode.h); the "
                        "base of airtwin.env.AirJetEnv.")
      .def(py::init([](const std::string& scenario_path, uint64_t seed,
                       std::shared_ptr<const CfdField> cfd, const std::string& air,
                       const std::string& drag, const std::vector<std::string>& object_physics,
                       const std::vector<std::string>& effects, const std::string& mjcf,
                       const std::string& table, const std::vector<std::string>& models,
                       bool vision, const std::string& calib, const std::string& calib_dir,
                       double vision_rate_hz, double noise_sigma_grey, double blur_sigma_px,
                       std::optional<bool> air_formation, double air_formation_time_scale,
                       const std::string& integrator, double air_front_co_flow,
                       double air_front_counter_flow, std::optional<bool> air_turbulence_swept,
                       const std::string& vary_physics, int planner_threads) {
             return std::make_unique<PyEpisode>(
                 scenario_path, seed,
                 TwinSetup{air, std::move(cfd), drag, object_physics, effects, mjcf, air_formation,
                           air_formation_time_scale, integrator, air_front_co_flow,
                           air_front_counter_flow, air_turbulence_swept},
                 ControllerSetup{table, models}, vision, calib, calib_dir, vision_rate_hz,
                 noise_sigma_grey, blur_sigma_px, vary_physics, planner_threads);
           }),
           py::arg("scenario_path"), py::arg("seed"), py::arg("cfd") = nullptr,
           py::arg("air") = "cfd", py::arg("drag") = "physical",
           py::arg("object_physics") = std::vector<std::string>{},
           py::arg("effects") = std::vector<std::string>{}, py::arg("mjcf") = "",
           py::arg("table") = "", py::arg("models") = std::vector<std::string>{},
           py::arg("vision") = false, py::arg("calib") = "", py::arg("calib_dir") = "",
           py::arg("vision_rate_hz") = 10.0, py::arg("noise_sigma_grey") = 0.0,
           py::arg("blur_sigma_px") = 0.0, py::arg("air_formation") = py::none(),
           py::arg("air_formation_time_scale") = AirTransportParameters{}.formation_time_scale,
           py::arg("integrator") = "euler",
           py::arg("air_front_co_flow") = AirTransportParameters{}.front_co_flow,
           py::arg("air_front_counter_flow") = AirTransportParameters{}.front_counter_flow,
           py::arg("air_turbulence_swept") = py::none(), py::arg("vary_physics") = "none",
           py::arg("planner_threads") = 1,
           "Set up as run_scenario (the twin's set-up as Twin's, the controller's table and "
           "models); vision: the controller sees "
           "through the detection pipeline on rendered frames (as --vision), with the camera "
           "model `calib` (a calib.yaml) or the twin's camera calibrated into `calib_dir`.")
      .def_property_readonly("finished", [](PyEpisode& e) { return e.episode().finished(); })
      .def_property_readonly(
          "done", [](PyEpisode& e) { return e.episode().controller().progress().done(); },
          "The controller saw the task done.")
      .def_property_readonly("time_s", [](PyEpisode& e) { return e.episode().time(); })
      .def_property_readonly("time_limit_s",
                             [](PyEpisode& e) { return e.scenario().task.time_limit_s; })
      .def_property_readonly("n_objects",
                             [](PyEpisode& e) { return e.scenario().scene.objects.size(); })
      .def_property_readonly(
          "reference_index",
          [](PyEpisode& e) { return e.episode().controller().progress().reference_index(); })
      .def_property_readonly(
          "servo_range_deg",
          [](PyEpisode& e) {
            const NozzleActuatorParameters& n = e.twin().nozzle;
            return std::array<double, 4>{rad_to_deg(n.pan_min_rad), rad_to_deg(n.tilt_min_rad),
                                         rad_to_deg(n.pan_max_rad), rad_to_deg(n.tilt_max_rad)};
          },
          "(pan_min, tilt_min, pan_max, tilt_max) of the servos (deg).")
      .def_property_readonly(
          "max_stagnation_radius_m",
          [](PyEpisode& e) { return max_stagnation_radius(e.field().geometry()); })
      .def_property_readonly("commanded_deg",
                             [](PyEpisode& e) {
                               const NozzleOrientation o =
                                   e.episode().twin().commanded_orientation();
                               return std::pair{rad_to_deg(o.pan_rad), rad_to_deg(o.tilt_rad)};
                             })
      .def(
          "known", [](PyEpisode& e) { return known(e.episode().controller()); },
          "What the controller knows: a dict of ids, types, positions (N x 2, m), velocities, "
          "references (the task's r_j), dynamics (N x 3), seen, weights, reach_m; id order.")
      .def(
          "states",
          [](PyEpisode& e) {
            const std::vector<ObjectMotion> motion = e.episode().twin().object_states();
            py::array_t<double> out({static_cast<py::ssize_t>(motion.size()), py::ssize_t{4}});
            double* row = out.mutable_data();
            for (const ObjectMotion& mo : motion) {
              *row++ = mo.p_W.x();
              *row++ = mo.p_W.y();
              *row++ = mo.v_W.x();
              *row++ = mo.v_W.y();
            }
            return out;
          },
          "N x 4: the twin's truth, x, y (m), vx, vy (m/s), in the scenario's order.")
      .def(
          "decide",
          [](PyEpisode& e) {
            py::gil_scoped_release release;
            return e.episode().decide();
          },
          "The shipped controller's next decision (its random stream advances).")
      .def(
          "step_decision",
          [](PyEpisode& e, const DecisionRecord& d) {
            py::gil_scoped_release release;
            e.episode().step(d);
          },
          py::arg("decision"), "One turn with the controller's decision, recorded as its own.")
      .def(
          "step_deg",
          [](PyEpisode& e, double pan_deg, double tilt_deg) {
            py::gil_scoped_release release;
            e.episode().step(NozzleOrientation{deg_to_rad(pan_deg), deg_to_rad(tilt_deg)});
          },
          py::arg("pan_deg"), py::arg("tilt_deg"), "One turn with the nozzle at (pan, tilt) deg.")
      .def(
          "step_at",
          [](PyEpisode& e, double x_m, double y_m) {
            py::gil_scoped_release release;
            e.episode().step_at({x_m, y_m});
          },
          py::arg("x_m"), py::arg("y_m"), "One turn with the stagnation point at (x, y) m.")
      .def_property_readonly(
          "last_cost", [](PyEpisode& e) { return e.episode().last_cost(); },
          "eq. (10) of the last turn on the positions reached.")
      .def_property_readonly("last_stagnation_point",
                             [](PyEpisode& e) {
                               const Eigen::Vector2d s = e.episode().last_stagnation_point();
                               return std::pair{s.x(), s.y()};
                             })
      .def("result", &PyEpisode::result, "The run so far as a RunResult.")
      .def("render", &PyEpisode::render,
           "The top camera's view of the twin now: H x W x 3 uint8, RGB, row 0 at the top.");
}

}  // namespace airtwin::python
