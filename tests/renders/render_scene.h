#pragma once
// Test scenes for renders/: the twin's own MJCF (sim/scene_builder.h) with a few objects, compiled
// and brought to a consistent kinematic state with mj_forward (no stepping: objects sit where the
// spec puts them, 0.2 mm above their rest height). Plus image measurements computed here, not by
// the code under test.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/mujoco_runtime.h"
#include "sim/scene_builder.h"

namespace airtwin::testing {

struct RenderScene {
  BuiltScene scene;
  DataPtr data;
  const mjModel* model() const { return scene.model.get(); }
  mjData* d() const { return data.get(); }
};

inline RenderScene make_render_scene(const std::vector<ObjectSpec>& objects, uint64_t seed = 3) {
  SceneSpec spec;
  spec.objects = objects;
  spec.source = "render test scene";
  RenderScene s{build_scene(spec, SceneParameters{}, seed), nullptr};
  s.data = make_data(s.scene.model.get());
  mj_forward(s.scene.model.get(), s.data.get());
  return s;
}

/// Mean of the bodies' centres of mass (xipos) of object i, world frame (m).
inline Eigen::Vector3d object_centre_W(const RenderScene& s, size_t i) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int b : s.scene.objects[i].bodies) {
    sum += Eigen::Vector3d(s.d()->xipos[3 * b], s.d()->xipos[3 * b + 1], s.d()->xipos[3 * b + 2]);
  }
  return sum / static_cast<double>(s.scene.objects[i].bodies.size());
}

/// Pixels brighter than `threshold` (grey level of the BGR image) within `radius_px` of `centre`.
struct Blob {
  int count = 0;
  Eigen::Vector2d centroid_px = Eigen::Vector2d::Zero();  ///< (column, row), pixel centres
};
inline Blob bright_blob(const cv::Mat& bgr, const Eigen::Vector2d& centre, double radius_px,
                        int threshold) {
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  Blob blob;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int r = 0; r < grey.rows; ++r) {
    for (int c = 0; c < grey.cols; ++c) {
      if (grey.at<unsigned char>(r, c) <= threshold) continue;
      if ((Eigen::Vector2d(c, r) - centre).norm() > radius_px) continue;
      ++blob.count;
      sum += Eigen::Vector2d(c, r);
    }
  }
  if (blob.count > 0) blob.centroid_px = sum / blob.count;
  return blob;
}

}  // namespace airtwin::testing
