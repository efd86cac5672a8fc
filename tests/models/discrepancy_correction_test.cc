// What the catalogue cannot name (models/discrepancy_correction.h, the analysis's step 5): data
// made by a plant with an effect outside the catalogue - a patch of floor with twice the
// friction, a jet whose speed pulses, a swirl that grows with the distance from s - must come out
// `unexplained`, with the structure found in the feature that carries it; data without such an
// effect must not. The plant is eq. (8) in vector form with the air's turbulence as a random
// Ornstein-Uhlenbeck gust (0.3 m/s per component, 0.1 s), integrated here: not the analysis's
// own predictor.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "common/units.h"
#include "models/discrepancy.h"
#include "tests/support/appendix_d_trials.h"
#include "tests/support/test_run.h"

namespace airtwin {
namespace {

enum class Outside { kNone, kFrictionPatch, kPulsingJet, kSwirl };

constexpr int kTrials = 200;        // Appendix D trials per data set
constexpr double kGustSigma = 0.3;  // m/s per horizontal component
constexpr double kGustTime = 0.1;   // s
const Eigen::Vector2d kPatchCentre(0.4, 0.0);
constexpr double kPatchRadius = 0.4;     // m: kinetic and static friction twice eq. (8)'s inside
constexpr double kPulseAmplitude = 0.4;  // air speed times 1 + A sin(2 pi t / T) after the re-aim
constexpr double kPulsePeriod = 0.5;     // s
// Air turned counter-clockwise by this times (r - kSwirlFrom) beyond kSwirlFrom from s.
constexpr double kSwirlPerMetre = deg_to_rad(120.0);
constexpr double kSwirlFrom = 0.3;  // m

// eq. (8) with Coulomb friction, semi-implicit Euler at 1 ms, the air gusting, and `effect`.
testing::Plant outside_plant(const AirFieldModel& field, Outside effect, std::uint64_t seed) {
  auto rng = std::make_shared<std::mt19937_64>(seed);
  return [&field, effect, rng](const NozzleTimeline& timeline, const WindowStart& start,
                               const std::vector<double>& times,
                               std::vector<Eigen::Vector2d>* positions) {
    const ObjectDynamics& xi = kTracerDynamics;
    std::normal_distribution<double> normal(0.0, 1.0);
    const double h = 1e-3, decay = std::exp(-h / kGustTime),
                 kick = kGustSigma * std::sqrt(1.0 - decay * decay);
    Eigen::Vector2d p = start.p_W, v = start.v_W,
                    gust(kGustSigma * normal(*rng), kGustSigma * normal(*rng));
    NozzleOrientation cached = timeline.effective(start.t_s);
    OrientedField f = field.at(cached);
    positions->assign(times.size(), p);
    size_t next = 0;
    for (double t = start.t_s; next < times.size(); t += h) {
      while (next < times.size() && times[next] <= t + 1e-12) (*positions)[next++] = p;
      const NozzleOrientation o = timeline.effective(t);
      if (o.pan_rad != cached.pan_rad || o.tilt_rad != cached.tilt_rad) {
        cached = o;
        f = field.at(o);
      }
      gust = decay * gust + kick * Eigen::Vector2d(normal(*rng), normal(*rng));
      Eigen::Vector2d u = f.velocity(p);
      double kinetic = -xi.xi3;
      if (effect == Outside::kFrictionPatch && (p - kPatchCentre).norm() < kPatchRadius) {
        kinetic *= 2.0;
      } else if (effect == Outside::kPulsingJet && t >= 0.0) {
        u *= 1.0 + kPulseAmplitude * std::sin(2.0 * kPi * t / kPulsePeriod);
      } else if (effect == Outside::kSwirl) {
        const double angle =
            kSwirlPerMetre * std::max(0.0, (p - f.stagnation_point()).norm() - kSwirlFrom);
        u = Eigen::Vector2d(std::cos(angle) * u.x() - std::sin(angle) * u.y(),
                            std::sin(angle) * u.x() + std::cos(angle) * u.y());
      }
      u += gust;
      const Eigen::Vector2d pull = xi.xi1 * v + xi.xi2 * u;
      if (v.squaredNorm() > 0.0) {
        const Eigen::Vector2d v_new = v + h * pull;
        const double speed = v_new.norm();
        if (speed <= h * kinetic) {
          v.setZero();
        } else {
          v = v_new * (1.0 - h * kinetic / speed);
        }
      } else if (pull.norm() > kinetic) {
        v = h * (pull.norm() - kinetic) / pull.norm() * pull;
      }
      p += h * v;
    }
  };
}

DiscrepancyReport analyse(const AirFieldModel& field, Outside effect, std::uint64_t seed) {
  const TrajectorySet set =
      testing::appendix_d_trials(field, kTrials, seed, outside_plant(field, effect, seed + 1000));
  DiscrepancyOptions o;
  o.seed = seed;
  DiscrepancyReport r = analyse_discrepancy(set, field, {{"tracer", kTracerDynamics}}, o);
  std::printf("found:");
  for (const std::string& f : r.found) std::printf(" %s", f.c_str());
  std::printf("%s; unexplained %d\n", r.found.empty() ? " none" : "", r.unexplained ? 1 : 0);
  for (size_t i = 0; i < r.corrections.size(); ++i) {
    const ResidualCorrection& c = r.corrections[i];
    std::printf("  %-20s%s bw %.2f cv %.3f held %.3f p %.2g rms %.2f: %s\n", c.feature.c_str(),
                static_cast<int>(i) == r.chosen_correction ? "*" : " ", c.bandwidth, c.cv_gain,
                c.heldout_gain, c.p_value, c.heldout_rms_mps2, c.where.c_str());
  }
  return r;
}

// Each case at the run's test seed in CI; over ten seeds from it in the acceptance tier, where
// the rate of `unexplained` must reach `floor` of ten (at most `floor` for data without an
// outside effect) and the structure must be found in `feature` as often.
void check(Outside effect, const std::string& feature, int floor) {
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  const bool sweep = testing::acceptance_tier();
  const int runs = sweep ? 10 : 1;
  int unexplained = 0, located = 0;
  for (int i = 0; i < runs; ++i) {
    const DiscrepancyReport r = analyse(field, effect, testing::test_seed() + 101 * i);
    ASSERT_TRUE(r.decidable);
    EXPECT_GT(r.n_acceleration_samples, 1000u);
    unexplained += r.unexplained ? 1 : 0;
    located += r.unexplained && r.chosen_correction >= 0 &&
               r.corrections[static_cast<size_t>(r.chosen_correction)].feature == feature;
  }
  std::printf("unexplained in %d of %d runs, in %s in %d\n", unexplained, runs, feature.c_str(),
              located);
  if (effect == Outside::kNone) {
    EXPECT_LE(unexplained, sweep ? floor : 0);
  } else {
    EXPECT_GE(unexplained, sweep ? floor : runs);
    EXPECT_GE(located, sweep ? floor : runs);
  }
}

TEST(DiscrepancyCorrection, GustsAloneLeaveNothingUnexplained) { check(Outside::kNone, "", 1); }

TEST(DiscrepancyCorrection, FrictionPatchIsUnexplainedAndOnTheFloor) {
  check(Outside::kFrictionPatch, "floor_position", 9);
}

TEST(DiscrepancyCorrection, PulsingJetIsUnexplainedAndInTime) {
  check(Outside::kPulsingJet, "time_since_command", 9);
}

TEST(DiscrepancyCorrection, SwirlIsUnexplainedAndAroundS) {
  check(Outside::kSwirl, "position_from_s", 9);
}

}  // namespace
}  // namespace airtwin
