#include "controller/run_metrics.h"

#include <algorithm>
#include <cmath>

namespace airtwin {

RunMetrics::RunMetrics(const TaskSpec& task) : task_(task), zones_(task) {}

void RunMetrics::add_frame(double t_s, const std::vector<Eigen::Vector2d>& p_W,
                           const std::vector<std::string>& types) {
  ++frames_;
  bool moved = still_from_W_.size() != p_W.size();
  for (size_t j = 0; j < p_W.size() && !moved; ++j) {
    moved = (p_W[j] - still_from_W_[j]).norm() > kStillDistance_m;
  }
  if (moved) {
    still_from_W_ = p_W;
    still_since_s_ = t_s;
  }
  if (task_.kind == TaskKind::kPath) {
    for (const auto& p : p_W) {
      const double e = distance_to_path(task_.path_W, p);
      sum_ += e;
      sum_sq_ += e * e;
      max_ = std::max(max_, e);
      ++count_;
    }
  }
  max_pairwise_m_ = std::max(max_pairwise_m_, max_pairwise_distance(p_W));
  last_in_zone_ = zones_.objects_in_zone(p_W, types);
}

ErrorStats RunMetrics::path_error() const {
  ErrorStats s;
  s.count = count_;
  if (count_ == 0) return s;
  const double n = static_cast<double>(count_);
  s.mean = sum_ / n;
  s.std = count_ > 1 ? std::sqrt(std::max(0.0, (sum_sq_ - n * s.mean * s.mean) / (n - 1.0))) : 0.0;
  s.max = max_;
  return s;
}

}  // namespace airtwin
