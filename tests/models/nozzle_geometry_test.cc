// eqs. (1)-(2) and their inverse.

#include "models/nozzle_geometry.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {
namespace {

NozzleOrientation deg(double pan, double tilt) { return {deg_to_rad(pan), deg_to_rad(tilt)}; }

// Reference values computed by hand (independently, in double precision) from
// c = h tan(phi) [cos theta, sin theta] and |s| = |c| - 0.1 |c|^2.33 with h = 1.43 m.
struct HandCase {
  double pan_deg, tilt_deg, cx, cy, sx, sy;
};
const HandCase kHand[] = {
    {90, 22.5, 0.0, 0.5923253941935259, 0.0, 0.5628088424106632},
    {-135, 45, -1.0111626970967627, -1.0111626970967629, -0.8484513017369694, -0.8484513017369695},
    {30, 10, 0.21836621187257924, 0.12607379120655243, 0.2148717014870427, 0.124056234694777},
};

TEST(NozzleGeometry, ProjectionAndStagnationMatchHandValues) {
  const NozzleGeometry g;
  for (const HandCase& h : kHand) {
    SCOPED_TRACE(testing::Message() << "pan " << h.pan_deg << " tilt " << h.tilt_deg);
    const Eigen::Vector2d c = projection_point(g, deg(h.pan_deg, h.tilt_deg));
    const Eigen::Vector2d s = stagnation_point(g, deg(h.pan_deg, h.tilt_deg));
    EXPECT_NEAR(c.x(), h.cx, 1e-12);
    EXPECT_NEAR(c.y(), h.cy, 1e-12);
    EXPECT_NEAR(s.x(), h.sx, 1e-12);
    EXPECT_NEAR(s.y(), h.sy, 1e-12);
  }
}

TEST(NozzleGeometry, StagnationPointSatisfiesEquationTwo) {
  // s on the segment from the origin to c, at distance a1 |c|^a2 from c.
  const NozzleGeometry g;
  for (double tilt = 1; tilt <= 60; tilt += 7) {
    for (double pan = -180; pan <= 180; pan += 45) {
      const Eigen::Vector2d c = projection_point(g, deg(pan, tilt));
      const Eigen::Vector2d s = stagnation_point(g, deg(pan, tilt));
      EXPECT_NEAR((c - s).norm(), g.a1 * std::pow(c.norm(), g.a2), 1e-12);
      EXPECT_NEAR(c.x() * s.y() - c.y() * s.x(), 0.0, 1e-12);  // collinear with the origin
      EXPECT_GT(s.dot(c), 0.0);                                // same side of the origin
      EXPECT_LT(s.norm(), c.norm());                           // displaced toward the origin
    }
  }
}

TEST(NozzleGeometry, StraightDownPutsBothPointsAtTheOrigin) {
  const NozzleGeometry g;
  EXPECT_EQ(projection_point(g, deg(37, 0)).norm(), 0.0);
  EXPECT_EQ(stagnation_point(g, deg(37, 0)).norm(), 0.0);
}

TEST(NozzleGeometry, InverseRoundTripOverReachableDisc) {
  const NozzleGeometry g;
  const double r_max = max_stagnation_radius(g);
  EXPECT_NEAR(r_max, 1.6493112635159837, 1e-12);  // hand value for tilt 60 deg
  double worst = 0.0;
  int n = 0;
  for (double x = -1.6; x <= 1.6; x += 0.05) {
    for (double y = -1.6; y <= 1.6; y += 0.05) {
      const Eigen::Vector2d s(x, y);
      if (s.norm() > r_max) continue;
      const AimResult r = aim_at_stagnation(g, s);
      ASSERT_TRUE(r.reachable()) << x << "," << y << ": " << r.unreachable_reason;
      EXPECT_GE(r.orientation->tilt_rad, g.tilt_min_rad);
      EXPECT_LE(r.orientation->tilt_rad, g.tilt_max_rad);
      worst = std::max(worst, (stagnation_point(g, *r.orientation) - s).norm());
      ++n;
    }
  }
  EXPECT_GT(n, 3000);
  EXPECT_LT(worst, 1e-9);
}

TEST(NozzleGeometry, InverseAtTheEdgeAndAtTheOrigin) {
  const NozzleGeometry g;
  const Eigen::Vector2d edge = max_stagnation_radius(g) * Eigen::Vector2d(0.6, -0.8);
  const AimResult r = aim_at_stagnation(g, edge);
  ASSERT_TRUE(r.reachable());
  EXPECT_NEAR(r.orientation->tilt_rad, g.tilt_max_rad, 1e-9);
  const AimResult o = aim_at_stagnation(g, Eigen::Vector2d::Zero(), deg_to_rad(45));
  ASSERT_TRUE(o.reachable());
  EXPECT_EQ(o.orientation->tilt_rad, 0.0);
  EXPECT_NEAR(o.orientation->pan_rad, deg_to_rad(45), 1e-15);
}

TEST(NozzleGeometry, UnreachableTargetsAreRejectedWithAReason) {
  NozzleGeometry g;
  const AimResult far = aim_at_stagnation(g, {2.0, 0.5});
  EXPECT_FALSE(far.reachable());
  EXPECT_NE(far.unreachable_reason.find("outside the reachable disc"), std::string::npos);
  EXPECT_FALSE(aim_at_stagnation(g, {NAN, 0.0}).reachable());
  EXPECT_FALSE(aim_at_stagnation(g, {INFINITY, 0.0}).reachable());
  // A minimum tilt leaves a hole around the origin.
  g.tilt_min_rad = deg_to_rad(10);
  const AimResult hole = aim_at_stagnation(g, {0.05, 0.0});
  EXPECT_FALSE(hole.reachable());
  EXPECT_NE(hole.unreachable_reason.find("below the minimum"), std::string::npos);
}

TEST(NozzleGeometry, ValidateRejectsImpossibleRigs) {
  NozzleGeometry g;
  EXPECT_NO_THROW(g.validate());
  g.tilt_max_rad = deg_to_rad(70);  // beyond eq. (2)'s fold at 64.4 deg
  EXPECT_THROW(g.validate(), InputError);
  g = NozzleGeometry{};
  g.height_m = -1;
  EXPECT_THROW(g.validate(), InputError);
  g = NozzleGeometry{};
  g.a2 = 1.0;
  EXPECT_THROW(g.validate(), InputError);
}

TEST(NozzleGeometry, WrapAngle) {
  EXPECT_NEAR(wrap_angle(3 * kPi / 2), -kPi / 2, 1e-15);
  EXPECT_NEAR(wrap_angle(-kPi), kPi, 1e-15);
  EXPECT_NEAR(wrap_angle(0.3), 0.3, 1e-15);
}

}  // namespace
}  // namespace airtwin
