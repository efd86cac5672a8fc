#pragma once
// Test support for vision/: frames of the twin with known object positions, and the scoring of
// detections against them. The truth comes from the simulation (object positions) and the
// renderer's ground-truth camera; the code under test sees neither.
//  - camera_from_truth: a CalibratedCamera made of the true K and pose (MuJoCo's camera frame
//    x right, y up, z back turned into OpenCV's x right, y down, z forward), to test detection
//    without calibration error;
//  - scattered_layout: objects at seeded random places, apart from each other, clear of the
//    nozzle rig and of the image's edge;
//  - PosedScene: a compiled scene whose objects are then moved to any place (touching, even
//    overlapping: nothing is stepped), truth = Twin's object position (area-weighted body
//    centres of mass);
//  - score: greedy nearest matching within a radius, per kind.

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <string>
#include <tuple>
#include <vector>

#include "common/random_stream.h"
#include "renders/camera_model.h"
#include "sim/mujoco_runtime.h"
#include "sim/scene_builder.h"
#include "vision/calibrated_camera.h"
#include "vision/object_detector.h"

namespace airtwin::testing {

inline CalibratedCamera camera_from_truth(const GroundTruthCamera& truth) {
  CalibratedCamera c;
  c.width_px = truth.width_px();
  c.height_px = truth.height_px();
  c.K = truth.intrinsics();
  const Eigen::Matrix3d mujoco_to_opencv = Eigen::Vector3d(1, -1, -1).asDiagonal();
  c.R_CW = mujoco_to_opencv * truth.R_WC().transpose();
  c.t_C = -c.R_CW * truth.p_WC();
  return c;
}

/// `n` objects, every `cotton_every`-th a wad (0: none), at least `spacing_m` apart, within
/// |x|, |y| <= extent_m and farther than 0.15 m from the rig's foot.
inline std::vector<ObjectSpec> scattered_layout(int n, int cotton_every, uint64_t seed,
                                                double spacing_m = 0.15, double extent_m = 1.2) {
  RandomStream rng(seed, RandomPurpose::kScenario, 0);
  std::vector<ObjectSpec> objects;
  int attempts = 0;
  while (static_cast<int>(objects.size()) < n && attempts++ < 100000) {
    const Eigen::Vector2d p(rng.uniform(-extent_m, extent_m), rng.uniform(-extent_m, extent_m));
    if (p.norm() < 0.15) continue;
    bool clear = true;
    for (const ObjectSpec& o : objects) clear = clear && (o.p_W - p).norm() >= spacing_m;
    if (!clear) continue;
    const int k = static_cast<int>(objects.size());
    std::string id = "o";
    id += std::to_string(k);
    objects.push_back(
        {id, cotton_every > 0 && k % cotton_every == 0 ? "cotton" : "tracer", p, std::nullopt});
  }
  return objects;
}

/// The object position the twin reports (Twin::object_state): the area-weighted mean of the
/// bodies' centres of mass, x and y (m).
inline Eigen::Vector2d object_position_W(const mjData* d, const SceneObject& o) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (size_t k = 0; k < o.bodies.size(); ++k) {
    const int b = o.bodies[k];
    const double w = o.area_share.empty() ? 1.0 / o.bodies.size() : o.area_share[k];
    sum += w * Eigen::Vector2d(d->xipos[3 * b], d->xipos[3 * b + 1]);
  }
  return sum;
}

/// A scene built with its objects spread apart (valid for the scene builder), then each moved to
/// its wanted place by its free joint (touching, even overlapping), and left to settle under
/// gravity for settle_s without air as Twin does before t = 0 (wads sag by ~1 cm: the height of
/// their visible centre is that of a settled wad), then brought up to date with mj_forward.
struct PosedScene {
  BuiltScene scene;
  DataPtr data;
  const mjModel* model() const { return scene.model.get(); }
  const mjData* d() const { return data.get(); }
  Eigen::Vector2d truth(size_t i) const { return object_position_W(d(), scene.objects[i]); }
};

inline PosedScene make_posed_scene(const std::vector<ObjectSpec>& wanted, uint64_t seed,
                                   double settle_s = 0.5) {
  SceneSpec spec;
  spec.source = "posed vision test scene";
  for (size_t i = 0; i < wanted.size(); ++i) {
    ObjectSpec o = wanted[i];
    o.p_W = {-1.5 + 0.2 * static_cast<double>(i % 16), -1.5 + 0.2 * static_cast<double>(i / 16)};
    spec.objects.push_back(o);
  }
  PosedScene s{build_scene(spec, SceneParameters{}, seed), nullptr};
  s.data = make_data(s.model());
  for (size_t i = 0; i < wanted.size(); ++i) {
    const int body = s.scene.objects[i].root_body;
    const int q = s.model()->jnt_qposadr[s.model()->body_jntadr[body]];
    s.data->qpos[q] = wanted[i].p_W.x();
    s.data->qpos[q + 1] = wanted[i].p_W.y();
  }
  while (s.data->time < settle_s) mj_step(s.model(), s.data.get());
  mj_forward(s.model(), s.data.get());
  return s;
}

struct TruthObject {
  Eigen::Vector2d p_W;
  ObjectKind kind;
};

struct Score {
  int objects = 0;
  int detected = 0;         ///< objects with a detection within the radius
  int wrong_kind = 0;       ///< of those, classified as the other kind
  int false_positives = 0;  ///< detections matched to no object
  double sum_error_m = 0.0;
  double max_error_m = 0.0;
  double mean_error_m() const { return detected > 0 ? sum_error_m / detected : 0.0; }
  double rate() const { return objects > 0 ? static_cast<double>(detected) / objects : 0.0; }
  void add(const Score& s) {
    objects += s.objects;
    detected += s.detected;
    wrong_kind += s.wrong_kind;
    false_positives += s.false_positives;
    sum_error_m += s.sum_error_m;
    max_error_m = std::max(max_error_m, s.max_error_m);
  }
};

/// Matches detections to objects, closest pairs first, each at most once, within radius_m.
inline Score score(const std::vector<Detection>& detections, const std::vector<TruthObject>& truth,
                   double radius_m = 0.015) {
  struct Pair {
    double distance;
    size_t object, detection;
  };
  std::vector<Pair> pairs;
  for (size_t i = 0; i < truth.size(); ++i) {
    for (size_t j = 0; j < detections.size(); ++j) {
      const double d = (detections[j].p_W - truth[i].p_W).norm();
      if (d <= radius_m) pairs.push_back({d, i, j});
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
    return a.distance != b.distance
               ? a.distance < b.distance
               : std::tie(a.object, a.detection) < std::tie(b.object, b.detection);
  });
  std::vector<char> object_used(truth.size(), 0), detection_used(detections.size(), 0);
  Score s;
  s.objects = static_cast<int>(truth.size());
  for (const Pair& p : pairs) {
    if (object_used[p.object] || detection_used[p.detection]) continue;
    object_used[p.object] = detection_used[p.detection] = 1;
    ++s.detected;
    s.sum_error_m += p.distance;
    s.max_error_m = std::max(s.max_error_m, p.distance);
    if (detections[p.detection].kind != truth[p.object].kind) ++s.wrong_kind;
  }
  for (char used : detection_used) s.false_positives += used ? 0 : 1;
  return s;
}

}  // namespace airtwin::testing
