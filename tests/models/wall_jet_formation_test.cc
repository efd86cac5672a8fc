// The wall jet's formation: the fit recovers tau from pulses made by its own defining equation;
// fitted to three of the shipped CFD pulses (100, 200, 400 ms), it predicts the peaks of the
// others (the held-out lengths) near s; the reader keeps probes only out to where the pulse's
// air had arrived before its run ended; bad files.

#include "models/wall_jet_formation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "common/errors.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

const std::string kData = AIRTWIN_SOURCE_DIR "/data/cfd";

TEST(WallJetFormation, FitRecoversTauFromItsOwnEquation) {
  // tau 0.1 s at 0.1 m and 0.3 s at 0.5 m; three pulse lengths each; valve ramps of 20 ms.
  std::vector<CfdPulse> pulses;
  for (double ms : {60.0, 150.0, 400.0}) {
    CfdPulse p;
    p.pulse_s = ms / 1000.0;
    p.valve_s = 0.02;
    p.r_m = {0.1, 0.5};
    for (double tau : {0.1, 0.3}) p.peak_fraction.push_back(1.0 - std::exp(-p.effective_s() / tau));
    pulses.push_back(p);
  }
  const WallJetFormation f = WallJetFormation::fit(pulses);
  ASSERT_EQ(f.r_m().size(), 2u);
  EXPECT_NEAR(f.tau_s()[0], 0.1, 1e-6);
  EXPECT_NEAR(f.tau_s()[1], 0.3, 1e-6);
  EXPECT_NEAR(f.time_s(0.3), 0.2, 1e-6);   // linear between
  EXPECT_NEAR(f.time_s(0.01), 0.1, 1e-6);  // the nearest end's beyond
  EXPECT_NEAR(f.time_s(2.0), 0.3, 1e-6);
  EXPECT_NEAR(f.pulse_peak_fraction(0.1, 0.1), 1.0 - std::exp(-1.0), 1e-6);
  // An overshoot counts as the steady air: fractions above 1 are capped, not chased.
  pulses[2].peak_fraction = {1.1, 1.1};
  const WallJetFormation capped = WallJetFormation::fit(pulses);
  EXPECT_LT(capped.tau_s()[0], 0.1 + 1e-3);
}

TEST(WallJetFormation, ShippedPulsesPredictTheHeldOutLengthsNearS) {
  std::vector<CfdPulse> fit_on, held_out;
  for (const CfdPulse& p : WallJetFormation::read_pulses(kData)) {
    const int ms = static_cast<int>(std::lround(1000.0 * p.pulse_s));
    (ms == 100 || ms == 200 || ms == 400 ? fit_on : held_out).push_back(p);
  }
  ASSERT_EQ(fit_on.size(), 3u) << "expected the 100, 200 and 400 ms pulses in " << kData;
  ASSERT_FALSE(held_out.empty()) << "expected a pulse of another length in " << kData;
  const WallJetFormation f = WallJetFormation::fit(fit_on);
  // tau grows outward past the footprint: the pulse's air thins on its way (docs/cfd.md).
  EXPECT_LT(f.time_s(0.2), 0.13);
  EXPECT_GT(f.time_s(0.6), 1.5 * f.time_s(0.2));
  // The largest misfit within 0.1-0.6 m of s, where the twin's objects meet sweeps.
  auto worst = [&](const CfdPulse& p, int* checked) {
    double w = 0.0;
    for (size_t i = 0; i < p.r_m.size(); ++i) {
      if (p.r_m[i] < 0.1 || p.r_m[i] > 0.6) continue;
      const double predicted = f.pulse_peak_fraction(p.effective_s(), p.r_m[i]);
      w = std::max(w, std::abs(predicted - std::min(1.0, p.peak_fraction[i])));
      ++*checked;
    }
    return w;
  };
  double fit_worst = 0.0;
  for (const CfdPulse& p : fit_on) {
    int checked = 0;
    fit_worst = std::max(fit_worst, worst(p, &checked));
  }
  // A first-order rise cannot follow the 400 ms head's overshoot (capped at 1): the fit is off
  // by ~0.15 there. The held-out lengths must be predicted as well as the fitted ones are fitted.
  EXPECT_LT(fit_worst, 0.2);
  for (const CfdPulse& p : held_out) {
    int checked = 0;
    const double w = worst(p, &checked);
    std::printf("held-out pulse %.0f ms: worst misfit %.3f at %d distances (fitted: %.3f)\n",
                1000.0 * p.pulse_s, w, checked, fit_worst);
    EXPECT_LE(w, fit_worst + 0.02) << p.pulse_s << " s";
    EXPECT_GT(checked, 10) << p.pulse_s << " s";
  }
}

TEST(WallJetFormation, ReaderStopsWhereThePulseWasStillArriving) {
  const std::string dir = testing::fresh_scratch_dir("wall_jet_formation_reader");
  const std::string path = dir + "/pulse100ms_tilt00_d40.json";
  std::ofstream(path) << R"({"pulse_s": 0.1, "valve_opening_s": 0.02, "end_time_s": 1.62,
    "probe_interval_s": 0.02, "figures": {"floor": [
      {"height_m": 0.015, "r_m": 0.1, "peak_t_s": 0.4, "peak_fraction": 0.9},
      {"height_m": 0.004, "r_m": 0.01, "peak_t_s": 0.4, "peak_fraction": null},
      {"height_m": 0.004, "r_m": 0.3, "peak_t_s": 0.6, "peak_fraction": 0.5},
      {"height_m": 0.004, "r_m": 0.1, "peak_t_s": 0.4, "peak_fraction": 0.55},
      {"height_m": 0.004, "r_m": 0.5, "peak_t_s": 1.62, "peak_fraction": 0.1},
      {"height_m": 0.004, "r_m": 0.7, "peak_t_s": 0.3, "peak_fraction": 0.02}]}})";
  const CfdPulse p = CfdPulse::read(path);
  EXPECT_EQ(p.r_m, (std::vector<double>{0.1, 0.3}));
  EXPECT_EQ(p.peak_fraction, (std::vector<double>{0.55, 0.5}));
  EXPECT_NEAR(p.effective_s(), 0.1 - 0.02 / 3.0, 1e-12);
  const std::vector<CfdPulse> all = WallJetFormation::read_pulses(dir);
  EXPECT_EQ(all.size(), 1u);
}

TEST(WallJetFormation, BadFilesAreOneClearError) {
  const std::string dir = testing::fresh_scratch_dir("wall_jet_formation_bad");
  auto expect_error = [&](const std::string& text, const std::string& needle) {
    const std::string path = dir + "/p.json";
    std::ofstream(path) << text;
    try {
      CfdPulse::read(path);
      ADD_FAILURE() << "no error for " << text;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      EXPECT_NE(what.find(needle), std::string::npos) << what;
    }
  };
  const std::string head =
      R"({"pulse_s": 0.1, "valve_opening_s": 0.02, "end_time_s": 1.62, "probe_interval_s": 0.02)";
  expect_error("{", "not JSON");
  expect_error("{}", "pulse_s");
  expect_error(R"({"pulse_s": 0.1, "valve_opening_s": 0.2, "end_time_s": 1.62,
                   "probe_interval_s": 0.02})",
               "valve_opening_s < pulse_s");
  expect_error(head + "}", "figures.floor");
  expect_error(head + R"(, "figures": {"floor": [{"height_m": 0.004, "r_m": "x"}]}})",
               "figures.floor[0]: field 'r_m'");
  expect_error(head + R"(, "figures": {"floor": [
      {"height_m": 0.004, "r_m": 0.1, "peak_t_s": 1.62, "peak_fraction": 0.5}]}})",
               "no floor probe");
  EXPECT_THROW(CfdPulse::read(dir + "/missing.json"), InputError);
  EXPECT_THROW(WallJetFormation::fit({}), InputError);
  EXPECT_THROW(WallJetFormation({0.2, 0.1}, {0.1, 0.1}), InputError);
  EXPECT_THROW(WallJetFormation({0.1}, {0.0}), InputError);
}

}  // namespace
}  // namespace airtwin
