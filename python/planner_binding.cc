// The CEM planner from Python (controller/cem_planner.h, section V-A, eq. 10): one decision on a
// planning problem given as arrays, the stagnation point and nozzle orientation out.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/errors.h"
#include "common/random_stream.h"
#include "common/units.h"
#include "controller/cem_planner.h"
#include "models/air_field.h"
#include "python/arrays.h"
#include "python/bindings.h"
#include "scenes/scenario.h"

namespace py = pybind11;

namespace airtwin::python {
namespace {

// The field the planner refers to, kept alive with it.
struct PyPlanner {
  std::shared_ptr<const AirFieldModel> field;
  CemPlanner planner;
};

std::vector<Eigen::Vector2d> points_of(const DoubleArray& a, py::ssize_t n,
                                       const std::string& what) {
  if (rows_of(a, 2, what) != n) {
    throw InputError(what + ": expected " + std::to_string(n) + " rows (one per object), got " +
                     std::to_string(a.shape(0)));
  }
  std::vector<Eigen::Vector2d> points(n);
  for (py::ssize_t j = 0; j < n; ++j) points[j] = {a.data()[2 * j], a.data()[2 * j + 1]};
  return points;
}

// The problem's arrays, copied into the library's types (a few doubles per object).
struct Problem {
  std::vector<Eigen::Vector2d> positions, velocities, references;
  std::vector<ObjectDynamics> dynamics;
  std::vector<double> weights, reach_m;  // empty: eq. (10)'s 1 and no limit
  std::optional<NozzleOrientation> nozzle_now;
  PlanningProblem view(int anchor, double pan_hint_deg) const {
    PlanningProblem p;
    p.positions_W = positions;
    p.velocities_W = velocities;
    p.references_W = references;
    p.dynamics = dynamics;
    p.weights = weights;
    p.reach_m = reach_m;
    p.nozzle_now = nozzle_now;
    p.anchor = anchor;
    p.pan_hint_rad = deg_to_rad(pan_hint_deg);
    return p;
  }
};

Problem problem_of(const DoubleArray& positions, const DoubleArray& references,
                   const DoubleArray& dynamics, const std::optional<DoubleArray>& velocities,
                   const std::optional<DoubleArray>& weights,
                   const std::optional<DoubleArray>& reach_m,
                   const std::optional<std::pair<double, double>>& nozzle_now_deg) {
  const py::ssize_t n = rows_of(positions, 2, "positions");
  Problem p;
  p.positions = points_of(positions, n, "positions");
  p.references = points_of(references, n, "references");
  p.velocities = velocities ? points_of(*velocities, n, "velocities")
                            : std::vector<Eigen::Vector2d>(n, Eigen::Vector2d::Zero());
  if (rows_of(dynamics, 3, "dynamics") != n) {
    throw InputError("dynamics: expected one row (xi1, xi2, xi3) per object, " + std::to_string(n) +
                     " rows, got " + std::to_string(dynamics.shape(0)));
  }
  for (py::ssize_t j = 0; j < n; ++j) {
    const double* xi = dynamics.data() + 3 * j;
    p.dynamics.push_back({xi[0], xi[1], xi[2]});
  }
  // Per-object weights and reaches (controller/cem_planner.h), when given.
  if (weights) {
    require_vector(*weights, n, "weights");
    p.weights.assign(weights->data(), weights->data() + n);
  }
  if (reach_m) {
    require_vector(*reach_m, n, "reach_m");
    p.reach_m.assign(reach_m->data(), reach_m->data() + n);
  }
  // The command the nozzle rests at (the transition's start, predict_transition).
  if (nozzle_now_deg) {
    p.nozzle_now =
        NozzleOrientation{deg_to_rad(nozzle_now_deg->first), deg_to_rad(nozzle_now_deg->second)};
  }
  return p;
}

std::unique_ptr<PyPlanner> make_planner(const AirFieldModel& field, const std::string& search,
                                        const Scenario* scenario) {
  CemParameters params;
  if (scenario != nullptr) {
    params = scenario->controller;
  } else if (search == "line") {
    params = CemParameters::line_defaults();
  } else if (search == "plane") {
    params = CemParameters::plane_defaults();
  } else {
    throw InputError("search: expected line or plane, got '" + search + "'");
  }
  auto shared = std::make_shared<const AirFieldModel>(field);
  CemPlanner planner(*shared, params);
  return std::unique_ptr<PyPlanner>(new PyPlanner{shared, std::move(planner)});
}

py::array_t<double> rows(const std::vector<Eigen::Vector2d>& points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), py::ssize_t{2}});
  double* row = out.mutable_data();
  for (const Eigen::Vector2d& p : points) {
    *row++ = p.x();
    *row++ = p.y();
  }
  return out;
}

}  // namespace

void bind_planner(py::module_& m) {
  py::class_<PlanResult>(m, "PlanResult", "One CEM decision (controller/cem_planner.h).")
      .def_property_readonly(
          "stagnation_point",
          [](const PlanResult& r) {
            return std::pair{r.stagnation_W.x(), r.stagnation_W.y()};
          },
          "s* (m), as (x, y).")
      .def_property_readonly("pan_deg",
                             [](const PlanResult& r) { return rad_to_deg(r.orientation.pan_rad); })
      .def_property_readonly("tilt_deg",
                             [](const PlanResult& r) { return rad_to_deg(r.orientation.tilt_rad); })
      .def_readonly("cost", &PlanResult::cost, "eq. (10) at s* (m; J_P when infeasible).")
      .def_readonly("iterations", &PlanResult::iterations)
      .def_readonly("evaluations", &PlanResult::evaluations)
      .def_readonly("converged", &PlanResult::converged)
      .def_readonly("blind_scan", &PlanResult::blind_scan,
                    "Line search with a scan pitch: no sample moved anything, and the floor was "
                    "scanned for a push that does not spread the objects.")
      .def_readonly("sweep_blocked", &PlanResult::sweep_blocked,
                    "With a sweep clearance: every push's re-aim passed an object, and the "
                    "decision is the paper's.")
      .def_property_readonly(
          "predicted_end", [](const PlanResult& r) { return rows(r.predicted_end_W); },
          "N x 2: where eqs. (8)-(9) put the objects after Delta T under s* (m).");

  py::class_<PyPlanner>(m, "CemPlanner",
                        "The cross-entropy-method planner over the stagnation point (eq. 10).")
      .def(py::init([](const AirFieldModel& field, const std::string& search,
                       const Scenario* scenario) { return make_planner(field, search, scenario); }),
           py::arg("field"), py::arg("search") = "line", py::arg("scenario") = nullptr,
           "The paper's parameters for the 'line' or 'plane' search, or a scenario's controller "
           "section (then `search` is the scenario's).")
      .def_property_readonly("horizon_s",
                             [](const PyPlanner& p) { return p.planner.parameters().horizon_s; })
      .def_property_readonly("penalty",
                             [](const PyPlanner& p) { return p.planner.parameters().penalty; })
      .def(
          "plan",
          [](const PyPlanner& p, const DoubleArray& positions, const DoubleArray& references,
             const DoubleArray& dynamics, const std::optional<DoubleArray>& velocities,
             std::uint64_t seed, std::uint64_t decision, int anchor, double pan_hint_deg,
             const std::optional<DoubleArray>& weights, const std::optional<DoubleArray>& reach_m,
             const std::optional<std::pair<double, double>>& nozzle_now_deg) {
            const Problem problem = problem_of(positions, references, dynamics, velocities, weights,
                                               reach_m, nozzle_now_deg);
            RandomStream rng(seed, RandomPurpose::kController, decision);
            py::gil_scoped_release release;
            return p.planner.plan(problem.view(anchor, pan_hint_deg), rng);
          },
          py::arg("positions"), py::arg("references"), py::arg("dynamics"),
          py::arg("velocities") = py::none(), py::arg("seed") = 1, py::arg("decision") = 0,
          py::arg("anchor") = -1, py::arg("pan_hint_deg") = 0.0, py::arg("weights") = py::none(),
          py::arg("reach_m") = py::none(), py::arg("nozzle_now_deg") = py::none(),
          "One decision: objects at positions (N x 2, m) with velocities (N x 2, m/s; default 0) "
          "and eq. (8)'s dynamics (N x 3) to be pushed toward references (N x 2, m); eq. (10) "
          "with per-object weights w_j (N, default 1) and reaches R_j (N, m from the point "
          "below the nozzle, default none); nozzle_now_deg, the (pan, tilt) the nozzle rests at, "
          "from which the re-aim is predicted when the parameters ask (predict_transition). The "
          "samples come from the stream (seed, controller, decision). A PlanResult.")
      .def(
          "cost",
          [](const PyPlanner& p, const DoubleArray& positions, const DoubleArray& references,
             const DoubleArray& dynamics, std::pair<double, double> s,
             const std::optional<DoubleArray>& velocities,
             const std::optional<DoubleArray>& weights, const std::optional<DoubleArray>& reach_m,
             const std::optional<std::pair<double, double>>& nozzle_now_deg) {
            const Problem problem = problem_of(positions, references, dynamics, velocities, weights,
                                               reach_m, nozzle_now_deg);
            std::vector<Eigen::Vector2d> end;
            double cost = 0.0;
            {
              py::gil_scoped_release release;
              cost = p.planner.cost(problem.view(-1, 0.0), {s.first, s.second}, &end);
            }
            return std::make_pair(cost, rows(end));
          },
          py::arg("positions"), py::arg("references"), py::arg("dynamics"),
          py::arg("stagnation_point"), py::arg("velocities") = py::none(),
          py::arg("weights") = py::none(), py::arg("reach_m") = py::none(),
          py::arg("nozzle_now_deg") = py::none(),
          "eq. (10) for the candidate s (m): (cost, N x 2 predicted ends), with weights and "
          "reaches and nozzle_now_deg as plan's; J_P, the penalty, when s is within delta_min of "
          "an object or out "
          "of the nozzle's reach.");
}

}  // namespace airtwin::python
