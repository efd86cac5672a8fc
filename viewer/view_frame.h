#pragma once
// What the live viewer's window shows of one camera frame of a run, as plain data: the twin's
// kinematic state (sim/kinematic_state.h, drawn by MuJoCo's visualiser on the window's own copy
// of the model) and the overlay (the task's path or zones, the references, the stagnation point,
// the air on the floor, a caption), in metres and the world frame. The simulation fills it
// (runs/run_view.h), the window draws it (viewer/viewer_window.h); in between it travels as bytes
// from one process to the other (viewer/viewer_channel.h, docs/viewer.md for why two processes).

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <mujoco/mujoco.h>

#include "sim/kinematic_state.h"
#include "sim/mujoco_runtime.h"

namespace airtwin {

/// A zone of the task on the floor (aggregation: one; sorting: one per object type).
struct ViewZone {
  Eigen::Vector2d centre_W = Eigen::Vector2d::Zero();  ///< m
  double radius_m = 0.0;
  std::string label;  ///< the object type for sorting, else empty
};

/// The air at one floor point.
struct ViewArrow {
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();  ///< m
  Eigen::Vector2d v_W = Eigen::Vector2d::Zero();  ///< m/s
};

struct ViewOverlay {
  std::vector<Eigen::Vector2d> path_W;                ///< the reference path (m), path tasks
  std::vector<Eigen::Vector2d> path_references_W;     ///< its reference points (m)
  std::vector<Eigen::Vector2d> current_references_W;  ///< the references being steered to (m)
  std::vector<ViewZone> zones;
  std::optional<Eigen::Vector2d> stagnation_W;  ///< s (m), once the controller has decided
  std::vector<ViewArrow> air;                   ///< the twin's mean air on a floor grid
  std::string caption;                          ///< one line: scenario, seed, decision count
};

struct ViewFrame {
  int64_t index = 0;  ///< the camera frame (40 Hz of simulated time; 0 at t = 0)
  KinematicState kinematics;
  ViewOverlay overlay;
};

/// The frame as bytes (host byte order: both ends are on one machine).
std::string encode_view_frame(const ViewFrame& frame);
/// Reads encode_view_frame's bytes. Throws InputError when they are truncated or malformed.
ViewFrame decode_view_frame(std::string_view bytes);

/// The compiled model as MuJoCo's binary MJB bytes (mj_saveModel): the window gets the very
/// model the twin steps, its meshes, textures and skins included.
std::string model_bytes(const mjModel* m);
/// The model of model_bytes. Throws InputError when MuJoCo cannot read it.
ModelPtr model_from_bytes(std::string_view bytes);

}  // namespace airtwin
