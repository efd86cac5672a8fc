// The air each point feels while the nozzle moves (sim/reached_air.h), against its definition:
// without the carried front and the formation, the field handed out is the CFD's air of the
// orientation the transport's reach search names (sim/air_transport.h), and no departure; with
// them, it is still the CFD's air of a kept orientation, built from that orientation alone, and
// a held nozzle leaves every point the present air once the kept history has passed.

#include "sim/reached_air.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "common/random_stream.h"
#include "common/units.h"
#include "tests/support/shipped_cfd.h"

namespace airtwin {
namespace {

std::shared_ptr<const CfdField> cfd() { return testing::shipped_cfd(); }

constexpr double kDt = 2.5e-3;  // s: the twin's step

// A seeded nozzle program: holds of 0.1-0.6 s, each followed by a slew to a new pan and tilt at
// the servos' 7 rad/s, so that points see orientations of every age the transport keeps.
std::vector<NozzleOrientation> program(uint64_t seed, double duration_s) {
  RandomStream rng(seed, RandomPurpose::kScenario, 0);
  std::vector<NozzleOrientation> out;
  NozzleOrientation o{0.0, deg_to_rad(20.0)};
  while (static_cast<double>(out.size()) * kDt < duration_s) {
    const int hold = static_cast<int>(rng.uniform(0.1, 0.6) / kDt);
    for (int i = 0; i < hold; ++i) out.push_back(o);
    const NozzleOrientation to{deg_to_rad(rng.uniform(-180.0, 180.0)),
                               deg_to_rad(rng.uniform(5.0, 40.0))};
    const double step = 7.0 * kDt;
    while (std::abs(to.pan_rad - o.pan_rad) > step || std::abs(to.tilt_rad - o.tilt_rad) > step) {
      o.pan_rad += std::clamp(to.pan_rad - o.pan_rad, -step, step);
      o.tilt_rad += std::clamp(to.tilt_rad - o.tilt_rad, -step, step);
      out.push_back(o);
    }
    o = to;
  }
  return out;
}

const std::vector<Eigen::Vector2d> kPoints = {{0.3, 0.2},   {-0.5, 0.4},  {0.9, -0.6},
                                              {-1.1, -0.2}, {0.05, 0.05}, {0.6, 1.0}};
constexpr double kZ = 0.0056;  // m: a tracer's centre

TEST(ReachedAir, EachPointGetsTheAirOfTheOrientationTheReachSearchNames) {
  AirTransportParameters params;
  params.formation = false;
  params.front_co_flow = 0.0;
  params.front_counter_flow = 0.0;
  const std::vector<NozzleOrientation> prog = program(11, 6.0);
  ReachedAir air(*cfd(), params, kDt, prog.front(), kPoints.size());
  int lagged = 0, steps_checked = 0;
  for (const NozzleOrientation& o : prog) {
    const CfdOrientedField present = cfd()->at(o);
    air.push(o, present);
    if (!air.begin_step()) continue;
    ++steps_checked;
    for (size_t i = 0; i < kPoints.size(); ++i) {
      const ReachedAir::PointAir a = air.at(i, kPoints[i], kZ);
      EXPECT_EQ(a.departure, Eigen::Vector2d::Zero());
      const int k = air.transport().reached_steps(kPoints[i]);
      const NozzleOrientation& want = air.transport().at_lag(k);
      const CfdOrientedField& got = a.field != nullptr ? *a.field : present;
      ASSERT_EQ(got.orientation().pan_rad, want.pan_rad) << "point " << i << ", lag " << k;
      ASSERT_EQ(got.orientation().tilt_rad, want.tilt_rad) << "point " << i << ", lag " << k;
      EXPECT_EQ(got.at(kPoints[i], kZ).u_W, cfd()->at(want).at(kPoints[i], kZ).u_W);
      if (k > 0) ++lagged;
    }
  }
  // The program must have exercised lagged air, not only the present one.
  EXPECT_GT(steps_checked, 1000);
  EXPECT_GT(lagged, 1000);
}

TEST(ReachedAir, WithTheCarriedFrontAndFormationTheFieldIsAKeptOrientationsOwnAir) {
  AirTransportParameters params;  // the defaults: carried front, formation at half the pulses'
  const std::vector<NozzleOrientation> prog = program(12, 6.0);
  ReachedAir air(*cfd(), params, kDt, prog.front(), kPoints.size());
  int departures = 0;
  for (const NozzleOrientation& o : prog) {
    const CfdOrientedField present = cfd()->at(o);
    air.push(o, present);
    if (!air.begin_step()) continue;
    for (size_t i = 0; i < kPoints.size(); ++i) {
      const ReachedAir::PointAir a = air.at(i, kPoints[i], kZ);
      if (a.departure != Eigen::Vector2d::Zero()) ++departures;
      if (a.field == nullptr) continue;
      // One of the kept orientations, and its air exactly as built from it alone.
      bool kept = false;
      for (int k = 0; k < air.transport().capacity() && !kept; ++k) {
        const NozzleOrientation& q = air.transport().at_lag(k);
        kept = q.pan_rad == a.field->orientation().pan_rad &&
               q.tilt_rad == a.field->orientation().tilt_rad;
      }
      ASSERT_TRUE(kept) << "point " << i;
      EXPECT_EQ(a.field->at(kPoints[i], kZ).u_W,
                cfd()->at(a.field->orientation()).at(kPoints[i], kZ).u_W);
    }
  }
  EXPECT_GT(departures, 100);
  // Held past the kept history, every point comes to feel the present air with nothing left
  // forming (departures decay at exp(-dt / tau), tau at most the pulses' longest; 20 s is
  // dozens of them).
  const NozzleOrientation last = prog.back();
  const CfdOrientedField present = cfd()->at(last);
  const int hold = air.transport().capacity() + static_cast<int>(20.0 / kDt);
  bool own = true;
  for (int s = 0; s < hold && own; ++s) {
    air.push(last, present);
    own = air.begin_step();
    for (size_t i = 0; own && i < kPoints.size(); ++i) air.at(i, kPoints[i], kZ);
  }
  EXPECT_FALSE(own);
}

}  // namespace
}  // namespace airtwin
