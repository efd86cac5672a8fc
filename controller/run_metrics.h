#pragma once
// The figures by which a closed-loop run is judged, the paper's (Table I and section V-C):
//  - path error: the distance (m) from each object to the reference path, every camera frame
//    from the start until the task is done; mean, standard deviation and maximum over all
//    objects and frames (path tasks only);
//  - maximum pairwise distance (m) between objects over the run (the octagon's "span" figure);
//  - objects in their zone at the end.
// Fed with the TRUE positions (the twin's, or a rig's external tracking), not the controller's.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "controller/task.h"

namespace airtwin {

struct ErrorStats {
  double mean = 0.0, std = 0.0, max = 0.0;
  long long count = 0;
};

class RunMetrics {
 public:
  explicit RunMetrics(const TaskSpec& task);

  /// One frame: every object's position (m) and type.
  void add_frame(const std::vector<Eigen::Vector2d>& p_W, const std::vector<std::string>& types);

  /// Path error statistics (m); count 0 for zone tasks.
  ErrorStats path_error() const;
  double max_pairwise_distance_m() const { return max_pairwise_m_; }
  /// Objects in their zone in the last frame (path tasks: within the switch distance of the
  /// path's end).
  int objects_in_zone() const { return last_in_zone_; }
  long long frames() const { return frames_; }

 private:
  TaskSpec task_;
  TaskProgress zones_;  // for objects_in_zone
  double sum_ = 0.0, sum_sq_ = 0.0, max_ = 0.0;
  long long count_ = 0;
  double max_pairwise_m_ = 0.0;
  int last_in_zone_ = 0;
  long long frames_ = 0;
};

}  // namespace airtwin
