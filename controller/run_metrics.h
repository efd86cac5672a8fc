#pragma once
// The figures by which a closed-loop run is judged, the paper's (Table I and section V-C):
//  - path error: the distance (m) from each object to the reference path, every camera frame
//    from the start until the task is done; mean, standard deviation and maximum over all
//    objects and frames (path tasks only);
//  - maximum pairwise distance (m) between objects over the run (the octagon's "span" figure);
//  - objects in their zone at the end;
//  - since when the objects have been still: from still_since_s() to the last frame no object
//    moved more than kStillDistance_m from where it was then. A run that fails still for long at
//    its end did not run out of time while progressing: the controller's pushes moved nothing
//    (a deadlock of the one-push plan, or air too weak where the objects lie).
// Fed with the TRUE positions (the twin's, or a rig's external tracking), not the controller's.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "controller/task.h"

namespace airtwin {

/// An object within this (m) of where it was counts as still: a hundredth of the floor a push
/// moves an object over (a tracer goes 10-50 cm), above the jitter of an object at rest.
inline constexpr double kStillDistance_m = 0.01;

struct ErrorStats {
  double mean = 0.0, std = 0.0, max = 0.0;
  long long count = 0;
};

class RunMetrics {
 public:
  explicit RunMetrics(const TaskSpec& task);

  /// One frame at time t_s (s, increasing): every object's position (m) and type.
  void add_frame(double t_s, const std::vector<Eigen::Vector2d>& p_W,
                 const std::vector<std::string>& types);

  /// Path error statistics (m); count 0 for zone tasks.
  ErrorStats path_error() const;
  double max_pairwise_distance_m() const { return max_pairwise_m_; }
  /// Objects in their zone in the last frame (path tasks: within the switch distance of the
  /// path's end).
  int objects_in_zone() const { return last_in_zone_; }
  long long frames() const { return frames_; }
  /// The time (s) of the frame from which on, up to the last frame, no object has moved more than
  /// kStillDistance_m from its position in that frame (restarted whenever one does, and when the
  /// number of objects changes); 0 before any frame.
  double still_since_s() const { return still_since_s_; }

 private:
  TaskSpec task_;
  TaskProgress zones_;  // for objects_in_zone
  double sum_ = 0.0, sum_sq_ = 0.0, max_ = 0.0;
  long long count_ = 0;
  double max_pairwise_m_ = 0.0;
  int last_in_zone_ = 0;
  long long frames_ = 0;
  std::vector<Eigen::Vector2d> still_from_W_;  // positions at still_since_s_
  double still_since_s_ = 0.0;
};

}  // namespace airtwin
