#pragma once
// The controller's view of a rig: the smallest interface through which it manipulates objects.
// The twin implements it (rigs/twin_rig.h: positions from its truth or from the vision pipeline on
// rendered frames); the physical rig would implement the same four calls over its servo bus,
// valve and camera.
//
//   observe()  the objects now: id, type, position and velocity on the floor (world frame, m, m/s),
//              as the perception sees them; objects it cannot see are left out.
//   aim(o)     command the nozzle's servos to orientation o (rad); returns at once, the servos
//              and the air follow at their own pace.
//   wait(dt)   let dt seconds of rig time pass (the twin steps; a rig sleeps, filming).
//   time()     rig time (s) since the run started.
//
// Units SI; angles in radians. Implementations throw InputError for an orientation outside the
// servos' range and SimulationError (or their own error) when the rig fails.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "models/nozzle_geometry.h"

namespace airtwin {

struct ObservedObject {
  std::string id;    ///< stable over a run (a tracker's id on a real rig)
  std::string type;  ///< "tracer" | "cotton"
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();  ///< m
  Eigen::Vector2d v_W = Eigen::Vector2d::Zero();  ///< m/s (0 when unknown)
};

struct Observation {
  double t_s = 0.0;
  std::vector<ObservedObject> objects;
  /// Objects the perception saw leave its view and has not seen come back (a camera: tracks
  /// ended at the image's edge minus tracks started there). While any is out, the task cannot
  /// be done: the objects still seen being in place says nothing of it.
  int out_of_view = 0;
};

class Rig {
 public:
  virtual ~Rig() = default;
  virtual Observation observe() = 0;
  virtual void aim(const NozzleOrientation& target) = 0;
  virtual void wait(double duration_s) = 0;
  virtual double time() const = 0;
};

}  // namespace airtwin
