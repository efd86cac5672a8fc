#pragma once
// The parts of the Python module `airtwin` (python/module.cc assembles them). Bindings are thin:
// they convert units at the edge (degrees where people type them, SI otherwise), check array
// shapes, release the GIL around the C++ work and hand arrays over without copies where the
// layout allows; the logic is the libraries'.

#include <mujoco/mujoco.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <opencv2/core.hpp>

#include "renders/frame_renderer.h"

namespace airtwin::python {

/// InputError (and FieldError, UsageError) -> ValueError with the same message.
void bind_errors(pybind11::module_& m);
/// Field (the analytical air field, eqs. 1-3), CfdField, aim and the stagnation point.
void bind_field(pybind11::module_& m);
/// Batch trajectory prediction (eqs. 8-9): predict(), Prediction, object_dynamics().
void bind_prediction(pybind11::module_& m);
/// Identification of a speed series (section IV): identify_series(), IdentifiedModel.
void bind_identification(pybind11::module_& m);
/// Scenario and Twin (the MuJoCo twin, its nozzle, states and camera frames).
void bind_twin(pybind11::module_& m);
/// CemPlanner and PlanResult: one CEM decision on a planning problem.
void bind_planner(pybind11::module_& m);
/// The renderer's frame of `data` as H x W x 3 uint8 RGB (the BGR frame into `bgr`, converted
/// into the returned array in one pass), the GIL released while it renders.
pybind11::array_t<std::uint8_t> rgb_frame(FrameRenderer& renderer, const mjData* data,
                                          int64_t frame_index, cv::Mat& bgr);

/// probe_air(): the twin's moving air at fixed floor points over a nozzle program.
void bind_probe(pybind11::module_& m);
/// manipulation_region() and Region: where the line search's pushes move an object.
void bind_region(pybind11::module_& m);

/// run_scenario and RunResult: a closed-loop run as `airtwin run` runs it.
void bind_run(pybind11::module_& m);

}  // namespace airtwin::python
