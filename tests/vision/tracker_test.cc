// Tracking on synthetic detections whose motion is known: ids kept through constant-velocity
// motion, crossings, missed frames and merges; velocities against the true ones; tracks ended as
// lost or out of view; the assignment solver against brute force.

#include "vision/tracker.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "common/errors.h"
#include "common/random_stream.h"

namespace airtwin {
namespace {

constexpr double kDt = 1.0 / 40.0;

// A detection at p_W; its pixel as the twin's top camera shows it (2.64 mm/px, origin at the
// image centre, +y up).
Detection at(const Eigen::Vector2d& p_W, ObjectKind kind = ObjectKind::kTracer) {
  Detection d;
  d.kind = kind;
  d.p_W = p_W;
  d.centre_px = {511.5 + p_W.x() / 0.00264, 511.5 - p_W.y() / 0.00264};
  return d;
}

TrackerOptions image_options() {
  TrackerOptions o;
  o.image_width_px = 1024;
  o.image_height_px = 1024;
  return o;
}

// The id given to the detection nearest p_W in the last update.
int id_near(const Tracker& tracker, const std::vector<Detection>& ds, const Eigen::Vector2d& p_W) {
  size_t best = 0;
  for (size_t j = 1; j < ds.size(); ++j) {
    if ((ds[j].p_W - p_W).norm() < (ds[best].p_W - p_W).norm()) best = j;
  }
  return tracker.detection_ids()[best];
}

TEST(Assignment, MatchesBruteForce) {
  RandomStream rng(5, RandomPurpose::kScenario, 1);
  for (const auto& [rows, cols] :
       std::vector<std::pair<int, int>>{{5, 5}, {4, 6}, {6, 4}, {1, 3}}) {
    for (int trial = 0; trial < 20; ++trial) {
      Eigen::MatrixXd cost(rows, cols);
      for (int i = 0; i < rows; ++i) {
        for (int j = 0; j < cols; ++j) cost(i, j) = std::floor(rng.uniform(0, 10));
      }
      const std::vector<int> a = solve_assignment(cost);
      // Its total and the best total over every injective map of the smaller side.
      double total = 0;
      std::vector<char> used(cols, 0);
      int assigned = 0;
      for (int i = 0; i < rows; ++i) {
        if (a[i] < 0) continue;
        ASSERT_LT(a[i], cols);
        ASSERT_FALSE(used[a[i]]);
        used[a[i]] = 1;
        total += cost(i, a[i]);
        ++assigned;
      }
      EXPECT_EQ(assigned, std::min(rows, cols));
      double best = 1e300;
      if (rows <= cols) {
        std::vector<int> perm(cols);
        std::iota(perm.begin(), perm.end(), 0);
        do {
          double t = 0;
          for (int i = 0; i < rows; ++i) t += cost(i, perm[i]);
          best = std::min(best, t);
        } while (std::next_permutation(perm.begin(), perm.end()));
      } else {
        std::vector<int> perm(rows);
        std::iota(perm.begin(), perm.end(), 0);
        do {
          double t = 0;
          for (int j = 0; j < cols; ++j) t += cost(perm[j], j);
          best = std::min(best, t);
        } while (std::next_permutation(perm.begin(), perm.end()));
      }
      EXPECT_DOUBLE_EQ(total, best) << rows << " x " << cols << ", trial " << trial;
    }
  }
}

TEST(Tracker, ConstantVelocityKeepsIdsAndMeasuresVelocity) {
  // Five objects 10 cm apart, each at its own velocity up to 0.8 m/s (2 cm per frame).
  std::vector<Eigen::Vector2d> p0, v;
  for (int k = 0; k < 5; ++k) {
    p0.emplace_back(-0.5 + 0.1 * k, 0.2 * std::sin(k));
    v.emplace_back(0.8 * std::cos(1.3 * k), 0.8 * std::sin(1.3 * k));
  }
  Tracker tracker(image_options());
  std::vector<int> ids(5, 0);
  for (int frame = 0; frame < 30; ++frame) {
    const double t = frame * kDt;
    std::vector<Detection> ds;
    for (int k = 4; k >= 0; --k) ds.push_back(at(p0[k] + v[k] * t));  // order should not matter
    tracker.update(t, ds);
    for (int k = 0; k < 5; ++k) {
      const int id = id_near(tracker, ds, p0[k] + v[k] * t);
      if (frame == 0) ids[k] = id;
      EXPECT_EQ(id, ids[k]) << "object " << k << ", frame " << frame;
    }
  }
  ASSERT_EQ(tracker.tracks().size(), 5u);
  for (const Track& track : tracker.tracks()) {
    const int k = static_cast<int>(std::find(ids.begin(), ids.end(), track.id) - ids.begin());
    ASSERT_LT(k, 5);
    EXPECT_LT((track.v_W - v[k]).norm(), 1e-9);
    EXPECT_EQ(track.hits, 30);
  }
  EXPECT_EQ(tracker.counters().new_tracks, 5);
  EXPECT_EQ(tracker.counters().missed, 0);
}

TEST(Tracker, NoisyVelocityHasTheLeastSquaresSpread) {
  // 1 mm of detection noise per axis on a straight track: the velocity's spread per axis must be
  // the least-squares one, sigma * sqrt([(A^T A)^-1]_11) for the window's design matrix A (rows
  // 1, tau, tau^2 at tau = -4 dt .. 0), ~13 mm/s for a line and ~50 mm/s for a parabola.
  for (const int degree : {1, 2}) {
    TrackerOptions o;
    o.velocity_degree = degree;
    Tracker tracker(o);
    RandomStream rng(3, RandomPurpose::kScenario, 2);
    const Eigen::Vector2d v(0.3, -0.2);
    double sum_sq = 0;
    int samples = 0;
    for (int frame = 0; frame < 2000; ++frame) {
      const double t = frame * kDt;
      const Eigen::Vector2d noise(0.001 * rng.normal(), 0.001 * rng.normal());
      tracker.update(t, {at(Eigen::Vector2d(-0.5, 0.1) + v * t + noise)});  // no image limits
      ASSERT_EQ(tracker.tracks().size(), 1u);
      if (frame < 5) continue;  // the window fills
      sum_sq += (tracker.tracks()[0].v_W - v).squaredNorm();
      samples += 2;
    }
    Eigen::MatrixXd A(5, degree + 1);
    for (int k = 0; k < 5; ++k) {
      for (int c = 0; c <= degree; ++c) A(k, c) = std::pow((k - 4) * kDt, c);
    }
    const double expected = 0.001 * std::sqrt((A.transpose() * A).inverse()(1, 1));
    EXPECT_NEAR(std::sqrt(sum_sq / samples), expected, 0.1 * expected) << "degree " << degree;
  }
}

TEST(Tracker, CrossingPathsKeepTheirIds) {
  // Two objects crossing at right angles through the same point at the same frame.
  Tracker tracker;
  int id_a = 0, id_b = 0;
  for (int frame = 0; frame < 40; ++frame) {
    const double t = frame * kDt;
    const Eigen::Vector2d a(-0.2 + 0.4 * t, 0.0), b(0.0, -0.2 + 0.4 * t);
    const std::vector<Detection> ds = {at(a), at(b)};
    tracker.update(t, ds);
    if (frame == 0) {
      id_a = tracker.detection_ids()[0];
      id_b = tracker.detection_ids()[1];
    }
    if ((a - b).norm() > 1e-12) {  // at the crossing both are one point: either id is right
      EXPECT_EQ(tracker.detection_ids()[0], id_a) << "frame " << frame;
      EXPECT_EQ(tracker.detection_ids()[1], id_b) << "frame " << frame;
    }
  }
  EXPECT_EQ(tracker.counters().new_tracks, 2);
}

TEST(Tracker, CoastsThroughMissedFramesThenIsLost) {
  TrackerOptions o;
  o.max_missed_frames = 8;
  Tracker tracker(o);
  const Eigen::Vector2d v(0.4, 0.0);  // 1 cm per frame
  auto p = [&](int frame) -> Eigen::Vector2d {
    return Eigen::Vector2d(-0.3, 0.2) + v * frame * kDt;
  };
  // Seen for 10 frames, missing for 6, seen again: same track, 6 misses.
  int frame = 0;
  for (; frame < 10; ++frame) tracker.update(frame * kDt, {at(p(frame))});
  for (; frame < 16; ++frame) {
    tracker.update(frame * kDt, {});
    ASSERT_EQ(tracker.tracks().size(), 1u);
    EXPECT_EQ(tracker.tracks()[0].missed_frames, frame - 9);
    EXPECT_LT((tracker.tracks()[0].predict(frame * kDt) - p(frame)).norm(), 1e-9);
  }
  tracker.update(frame * kDt, {at(p(frame))});
  EXPECT_EQ(tracker.detection_ids()[0], 1);
  EXPECT_EQ(tracker.counters().missed, 6);
  ++frame;
  // Then missing for longer than max_missed_frames: lost, and a later detection is a new track.
  for (int k = 0; k < 9; ++k, ++frame) tracker.update(frame * kDt, {});
  EXPECT_TRUE(tracker.tracks().empty());
  EXPECT_EQ(tracker.counters().lost, 1);
  ASSERT_EQ(tracker.ended().size(), 1u);
  EXPECT_EQ(tracker.ended()[0].id, 1);
  tracker.update(frame * kDt, {at(p(frame))});
  EXPECT_EQ(tracker.detection_ids()[0], 2);
}

TEST(Tracker, IdsSurviveABriefMerge) {
  // Two tracers side by side 3 cm apart moving together at 0.4 m/s; for 4 frames the detector
  // sees one blob and reports one object between them; then they are two again.
  Tracker tracker;
  const Eigen::Vector2d v(0.4, 0.1);
  auto a = [&](int f) -> Eigen::Vector2d { return Eigen::Vector2d(0.0, 0.3) + v * f * kDt; };
  auto b = [&](int f) -> Eigen::Vector2d { return Eigen::Vector2d(0.0, 0.33) + v * f * kDt; };
  int id_a = 0, id_b = 0;
  for (int f = 0; f < 30; ++f) {
    std::vector<Detection> ds;
    const bool merged = f >= 10 && f < 14;
    if (merged) {
      ds = {at(0.5 * (a(f) + b(f)))};
    } else {
      ds = {at(a(f)), at(b(f))};
    }
    tracker.update(f * kDt, ds);
    if (f == 0) {
      id_a = tracker.detection_ids()[0];
      id_b = tracker.detection_ids()[1];
    } else if (!merged) {
      EXPECT_EQ(tracker.detection_ids()[0], id_a) << "frame " << f;
      EXPECT_EQ(tracker.detection_ids()[1], id_b) << "frame " << f;
    }
  }
  EXPECT_EQ(tracker.counters().new_tracks, 2);
  EXPECT_EQ(tracker.counters().missed, 4);
  EXPECT_EQ(tracker.counters().merged, 4);
  EXPECT_EQ(tracker.counters().lost, 0);
}

TEST(Tracker, LeavingTheViewEndsTheTrackAtOnce) {
  Tracker tracker(image_options());
  const Eigen::Vector2d v(1.0, 0.0);
  int f = 0;
  // Moving right toward the image's edge (x = 1.35 m): detected up to x = 1.33 m.
  for (; 0.9 + v.x() * f * kDt <= 1.33; ++f)
    tracker.update(f * kDt, {at({0.9 + v.x() * f * kDt, 0.0})});
  EXPECT_EQ(tracker.tracks().size(), 1u);
  tracker.update(f * kDt, {});
  EXPECT_TRUE(tracker.tracks().empty());
  EXPECT_EQ(tracker.counters().left_view, 1);
  EXPECT_EQ(tracker.counters().lost, 0);
  EXPECT_EQ(tracker.counters().entered_view, 0);
  // Coming back in at the edge starts a track there.
  tracker.update((f + 1) * kDt, {at({1.33, 0.0})});
  EXPECT_EQ(tracker.counters().entered_view, 1);
}

TEST(Tracker, GateStartsANewTrackForAJump) {
  TrackerOptions o;
  o.max_jump_m = 0.05;
  Tracker tracker(o);
  tracker.update(0.0, {at({0.0, 0.0})});
  tracker.update(kDt, {at({0.2, 0.0})});  // 20 cm in one frame: another object
  EXPECT_EQ(tracker.detection_ids()[0], 2);
  EXPECT_EQ(tracker.counters().new_tracks, 2);
}

TEST(Tracker, KindIsTheMajorityVote) {
  Tracker tracker;
  const std::vector<ObjectKind> seen = {ObjectKind::kCotton, ObjectKind::kTracer,
                                        ObjectKind::kCotton, ObjectKind::kCotton,
                                        ObjectKind::kTracer};
  for (size_t f = 0; f < seen.size(); ++f) {
    tracker.update(f * kDt, {at({0.1, 0.1}, seen[f])});
    EXPECT_EQ(tracker.detection_ids()[0], 1);
  }
  EXPECT_EQ(tracker.tracks()[0].kind, ObjectKind::kCotton);
  EXPECT_EQ(tracker.tracks()[0].kind_votes[0], 2);
  EXPECT_EQ(tracker.tracks()[0].kind_votes[1], 3);
}

TEST(Tracker, SameInputSameIds) {
  auto run = [] {
    Tracker tracker;
    RandomStream rng(11, RandomPurpose::kScenario, 3);
    std::vector<int> ids;
    for (int f = 0; f < 20; ++f) {
      std::vector<Detection> ds;
      for (int k = 0; k < 8; ++k) {
        ds.push_back(at({0.1 * k + 0.002 * rng.normal(), 0.01 * f + 0.002 * rng.normal()}));
      }
      tracker.update(f * kDt, ds);
      ids.insert(ids.end(), tracker.detection_ids().begin(), tracker.detection_ids().end());
    }
    return ids;
  };
  EXPECT_EQ(run(), run());
}

TEST(Tracker, BadInputIsAnInputError) {
  Tracker tracker;
  tracker.update(1.0, {});
  EXPECT_THROW(tracker.update(1.0, {}), InputError);
  EXPECT_THROW(tracker.update(std::nan(""), {}), InputError);
  TrackerOptions o;
  o.max_jump_m = 0;
  EXPECT_THROW(Tracker{o}, InputError);
  o = {};
  o.velocity_window = 1;
  EXPECT_THROW(Tracker{o}, InputError);
}

}  // namespace
}  // namespace airtwin
