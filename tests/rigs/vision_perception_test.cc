// What the controller is told of the tracker's tracks (rigs/vision_perception.h, report_tracks):
// recent tracks only, at their predicted positions, and one object where two tracks sit closer
// than two objects can (a stretched wad peeled into a wad and a "tracer").

#include "rigs/vision_perception.h"

#include <gtest/gtest.h>

#include <vector>

namespace airtwin {
namespace {

Track track(int id, ObjectKind kind, Eigen::Vector2d p, Eigen::Vector2d v, double t_last) {
  Track t;
  t.id = id;
  t.kind = kind;
  t.p_W = p;
  t.v_W = v;
  t.t_last_s = t_last;
  return t;
}

TEST(ReportTracks, RecentTracksAtTheirPredictedPositions) {
  VisionPerceptionOptions o;
  const std::vector<Track> tracks = {
      track(2, ObjectKind::kCotton, {0.5, 0.0}, {0.1, 0.0}, 9.8),  // 0.2 s old: moved 2 cm
      track(1, ObjectKind::kTracer, {-0.5, 0.0}, {0.0, 0.0}, 10.0),
      track(3, ObjectKind::kTracer, {0.0, 0.5}, {0.0, 0.0}, 9.4)};  // 0.6 s unseen: withheld
  const TrackReport r = report_tracks(tracks, 10.0, o);
  ASSERT_EQ(r.objects.size(), 2u);
  EXPECT_EQ(r.duplicates, 0);
  // Oldest first.
  EXPECT_EQ(r.objects[0].id, "v1");
  EXPECT_EQ(r.objects[0].type, "tracer");
  EXPECT_EQ(r.objects[1].id, "v2");
  EXPECT_EQ(r.objects[1].type, "cotton");
  EXPECT_NEAR(r.objects[1].p_W.x(), 0.52, 1e-12);
  EXPECT_NEAR(r.objects[1].v_W.x(), 0.1, 1e-12);
}

TEST(ReportTracks, TheNewerOfTwoTracksOnOneObjectIsWithheld) {
  VisionPerceptionOptions o;
  o.min_separation_m = 0.025;
  // A wad (track 4) and a "tracer" born on its tail 1.5 cm away (track 7); a real tracer
  // touching the wad, 3.5 cm from its centre (track 5), stays.
  const std::vector<Track> tracks = {
      track(7, ObjectKind::kTracer, {0.215, 0.99}, {0.0, 0.0}, 10.0),
      track(4, ObjectKind::kCotton, {0.23, 0.99}, {0.0, 0.0}, 10.0),
      track(5, ObjectKind::kTracer, {0.23, 1.025}, {0.0, 0.0}, 10.0)};
  const TrackReport r = report_tracks(tracks, 10.0, o);
  ASSERT_EQ(r.objects.size(), 2u);
  EXPECT_EQ(r.objects[0].id, "v4");
  EXPECT_EQ(r.objects[0].type, "cotton");
  EXPECT_EQ(r.objects[1].id, "v5");
  EXPECT_EQ(r.duplicates, 1);
  // With the check off every track is reported.
  o.min_separation_m = 0.0;
  EXPECT_EQ(report_tracks(tracks, 10.0, o).objects.size(), 3u);
}

}  // namespace
}  // namespace airtwin
