// SINDy identification of eq. (8) from speed series made by the model itself.

#include "models/sindy.h"

#include <gtest/gtest.h>

#include <Eigen/QR>
#include <cmath>
#include <random>

#include "common/errors.h"
#include "common/units.h"
#include "models/air_field.h"

namespace airtwin {
namespace {

using Xi = Eigen::Matrix<double, kSindyTerms, 1>;

Xi model3(double xi1, double xi2, double xi3) {
  Xi xi = Xi::Zero();
  xi[0] = xi3;
  xi[1] = xi1;
  xi[2] = xi2;
  return xi;
}

// Speed series of objects released at rest along rays of the default field, integrated with a
// fine RK4 (independent of the identification code) and sampled at 40 Hz while moving.
SpeedPairs make_series(double xi1, double xi2, double xi3, int n_traj, std::uint64_t seed) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> start(0.2, 0.58), alpha(0, 2 * kPi), pan(-kPi, kPi);
  std::vector<double> v, va, vn, van;
  const double dt = 0.025;
  const int sub = 100;
  for (int t = 0; t < n_traj; ++t) {
    const OrientedField f = model.at({pan(rng), deg_to_rad(t % 2 ? 22.5 : 0.0)});
    const FieldCoefficients c = f.coefficients(alpha(rng));
    double r = start(rng), s = 0.0;  // position along the ray, speed
    std::vector<double> vs, vas;
    for (int k = 0; k < 80; ++k) {
      vs.push_back(s);
      vas.push_back(c.speed(r));
      const double h = dt / sub;
      for (int i = 0; i < sub; ++i) {
        auto acc = [&](double rr, double ss) { return xi1 * ss + xi2 * c.speed(rr) + xi3; };
        const double k1v = acc(r, s), k1r = s;
        const double k2v = acc(r + 0.5 * h * k1r, s + 0.5 * h * k1v), k2r = s + 0.5 * h * k1v;
        const double k3v = acc(r + 0.5 * h * k2r, s + 0.5 * h * k2v), k3r = s + 0.5 * h * k2v;
        const double k4v = acc(r + h * k3r, s + h * k3v), k4r = s + h * k3v;
        s += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
        r += h / 6 * (k1r + 2 * k2r + 2 * k3r + k4r);
        if (s <= 0) s = 0;  // friction wins: the object stops
      }
      if (s == 0 && k > 0) break;
    }
    for (size_t k = 0; k + 1 < vs.size(); ++k) {
      if (vs[k + 1] <= 0) break;
      v.push_back(vs[k]);
      va.push_back(vas[k]);
      vn.push_back(vs[k + 1]);
      van.push_back(vas[k + 1]);
    }
  }
  SpeedPairs d;
  d.dt_s = dt;
  d.v = Eigen::Map<Eigen::VectorXd>(v.data(), v.size());
  d.va = Eigen::Map<Eigen::VectorXd>(va.data(), va.size());
  d.v_next = Eigen::Map<Eigen::VectorXd>(vn.data(), vn.size());
  d.va_next = Eigen::Map<Eigen::VectorXd>(van.data(), van.size());
  return d;
}

void expect_recovered(const SindyResult& r, const Xi& truth, double rel_tol) {
  for (int j = 0; j < kSindyTerms; ++j) {
    if (truth[j] == 0.0) {
      EXPECT_EQ(r.continuous[j], 0.0) << "spurious term " << kTermNames[j];
    } else {
      EXPECT_NEAR(r.continuous[j], truth[j], rel_tol * std::abs(truth[j])) << kTermNames[j];
    }
  }
}

TEST(Sindy, LibraryHasTheTenNamedTerms) {
  EXPECT_STREQ(kTermNames[0], "1");
  EXPECT_STREQ(kTermNames[4], "v*vair");
  EXPECT_STREQ(kTermNames[9], "vair^3");
  const auto row = sindy_library_row(2.0, 3.0);
  EXPECT_EQ(row[3], 4.0);
  EXPECT_EQ(row[7], 12.0);
  EXPECT_EQ(row[9], 27.0);
}

TEST(Sindy, FlowStepMatchesTheLinearClosedForm) {
  // dv/dt = a v + c with va constant: v(dt) = (v0 + c/a) e^{a dt} - c/a.
  const Xi xi = model3(-2.66, 0.0, 1.5);
  const double v1 = sindy_flow_step(xi, 0.7, 2.0, 2.0, 0.025);
  const double a = -2.66, c = 1.5;
  EXPECT_NEAR(v1, (0.7 + c / a) * std::exp(a * 0.025) - c / a, 1e-12);
}

TEST(Sindy, NoiseFreeTracerRecoveredWithinHalfAPercentEveryMethod) {
  const SpeedPairs d = make_series(-2.66, 4.26, -8.53, 60, 1);
  ASSERT_GT(d.size(), 1000u);
  for (SindyMethod m : {SindyMethod::kStlsq, SindyMethod::kEsindy, SindyMethod::kRobust,
                        SindyMethod::kRobustEsindy}) {
    SCOPED_TRACE(sindy_method_name(m));
    SindyOptions o;
    o.method = m;
    const SindyResult r = identify_sindy(d, o);
    expect_recovered(r, model3(-2.66, 4.26, -8.53), 0.005);
    EXPECT_GT(r.r2, 0.99);
  }
}

TEST(Sindy, NoiseFreeCottonRecovered) {
  const SpeedPairs d = make_series(-4.25, 3.46, -4.12, 60, 2);
  const SindyResult r = identify_sindy(d, SindyOptions{});
  expect_recovered(r, model3(-4.25, 3.46, -4.12), 0.005);
}

// --terms: the regression keeps to the named terms. Noise-free cotton data: with eq. (8)'s three
// terms the model is recovered as with the whole library; without the constant the fit must do
// without it (its coefficient stays exactly 0, no bootstrap includes it) and no longer matches.
TEST(Sindy, RestrictedLibraryUsesOnlyTheGivenTerms) {
  const SpeedPairs d = make_series(-4.25, 3.46, -4.12, 60, 2);
  SindyOptions o;
  o.terms = parse_sindy_terms("1,v,vair");
  expect_recovered(identify_sindy(d, o), model3(-4.25, 3.46, -4.12), 0.005);
  o.terms = parse_sindy_terms("vair,v");  // any order
  const SindyResult r = identify_sindy(d, o);
  EXPECT_EQ(r.continuous[0], 0.0);
  EXPECT_EQ(r.inclusion[0], 0.0);
  for (int j = 3; j < kSindyTerms; ++j) EXPECT_EQ(r.continuous[j], 0.0) << kTermNames[j];
  EXPECT_GT(std::abs(r.continuous[2] - 3.46), 0.05 * 3.46);
}

TEST(Sindy, TermsParseByNameAndMustIncludeV) {
  const auto all = parse_sindy_terms("1,v,vair,v^2,v*vair,vair^2,v^3,v^2*vair,v*vair^2,vair^3");
  for (bool b : all) EXPECT_TRUE(b);
  const auto eq8 = parse_sindy_terms("vair,1,v");
  for (int j = 0; j < kSindyTerms; ++j) EXPECT_EQ(eq8[j], j < 3) << kTermNames[j];
  EXPECT_THROW(parse_sindy_terms("1,vair"), FieldError);     // no v
  EXPECT_THROW(parse_sindy_terms("1,v,v"), FieldError);      // twice
  EXPECT_THROW(parse_sindy_terms("1,v,vair2"), FieldError);  // unknown
  EXPECT_THROW(parse_sindy_terms("1,v,"), FieldError);       // empty name
  EXPECT_THROW(parse_sindy_terms(""), FieldError);
}

TEST(Sindy, SameSeedSameResultOtherSeedOtherBootstraps) {
  SpeedPairs d = make_series(-2.66, 4.26, -8.53, 40, 4);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (Eigen::Index k = 0; k < d.v.size(); ++k) d.v[k] *= 1 + noise(rng);
  SindyOptions o;
  o.seed = 11;
  const SindyResult a = identify_sindy(d, o), b = identify_sindy(d, o);
  EXPECT_EQ(a.continuous, b.continuous);
  EXPECT_EQ(a.discrete, b.discrete);
  // The bootstraps' rows are drawn before the fits run in parallel: any thread count, the same
  // bytes.
  for (int threads : {1, 2, 5}) {
    o.threads = threads;
    const SindyResult t = identify_sindy(d, o);
    EXPECT_EQ(t.discrete, a.discrete) << threads;
    EXPECT_EQ(t.inclusion, a.inclusion) << threads;
    EXPECT_EQ(t.weights, a.weights) << threads;
  }
  o.threads = 0;
  o.seed = 12;
  EXPECT_NE(identify_sindy(d, o).discrete, a.discrete);
}

// SindySolver::kFast (distinct rows with multiplicities, warm-started IRLS, the flow of all pairs
// at once) against kReference (robustfit's iteration literally), every method, on noisy speeds
// and on noisy speeds with +-5 sigma spikes in 5 % of the regressors: the discrete coefficients
// and the weights to 1e-6; the continuous ones to 1e-6 relative. The IRLS stops within ~1e-8 of
// its fixed point on either path, and the flow's rounding differs; Levenberg-Marquardt on an
// ill-conditioned support (the spiked data keep five to seven nearly collinear terms, coefficients
// up to 25) magnifies that to a few 1e-6 absolute, 1e-7 relative.
TEST(Sindy, FastSolverMatchesTheReference) {
  const SpeedPairs clean = make_series(-2.66, 4.26, -8.53, 60, 7);
  const double sigma = 0.05 * std::sqrt(clean.v.squaredNorm() / static_cast<double>(clean.size()));
  std::mt19937_64 rng(8);
  std::normal_distribution<double> noise(0.0, sigma);
  std::uniform_real_distribution<double> u(0, 1);
  SpeedPairs noisy = clean;
  for (Eigen::Index k = 0; k < noisy.v.size(); ++k) {
    noisy.v[k] += noise(rng);
    noisy.v_next[k] += noise(rng);
  }
  SpeedPairs spiked = noisy;
  int spikes = 0;
  for (Eigen::Index k = 0; k < spiked.v.size(); ++k) {
    if (u(rng) < 0.05) {
      spiked.v[k] += (u(rng) < 0.5 ? -5 : 5) * sigma;
      ++spikes;
    }
  }
  ASSERT_GT(spikes, 50);
  for (const SpeedPairs* d : {&noisy, &spiked}) {
    for (SindyMethod m : {SindyMethod::kStlsq, SindyMethod::kEsindy, SindyMethod::kRobust,
                          SindyMethod::kRobustEsindy}) {
      SCOPED_TRACE(std::string(d == &noisy ? "noisy " : "spiked ") + sindy_method_name(m));
      SindyOptions o;
      o.method = m;
      o.solver = SindySolver::kReference;
      const SindyResult ref = identify_sindy(*d, o);
      o.solver = SindySolver::kFast;
      const SindyResult fast = identify_sindy(*d, o);
      EXPECT_LE((fast.discrete - ref.discrete).cwiseAbs().maxCoeff(), 1e-6);
      for (int j = 0; j < kSindyTerms; ++j) {
        EXPECT_NEAR(fast.continuous[j], ref.continuous[j],
                    1e-6 * std::max(1.0, std::abs(ref.continuous[j])))
            << kTermNames[j];
      }
      EXPECT_EQ(fast.inclusion, ref.inclusion);
      EXPECT_LE((fast.weights - ref.weights).cwiseAbs().maxCoeff(), 1e-6);
      EXPECT_NEAR(fast.r2, ref.r2, 1e-9);
    }
  }
}

TEST(Sindy, BisquareIgnoresOutliersInTheTarget) {
  // y = 2 + 3x with 10% gross outliers in y: bisquare recovers the line, OLS does not.
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  Eigen::MatrixXd X(200, 2);
  Eigen::VectorXd y(200);
  for (int i = 0; i < 200; ++i) {
    X(i, 0) = 1;
    X(i, 1) = u(rng);
    y[i] = 2 + 3 * X(i, 1) + 0.01 * (u(rng) - 0.5) + (i % 10 == 0 ? 5.0 : 0.0);
  }
  Eigen::VectorXd w;
  const Eigen::VectorXd b = bisquare_fit(X, y, &w);
  EXPECT_NEAR(b[0], 2.0, 0.01);
  EXPECT_NEAR(b[1], 3.0, 0.01);
  EXPECT_EQ(w[0], 0.0);  // the outliers get zero weight
  EXPECT_GT(w[1], 0.5);
  const Eigen::VectorXd ols = X.colPivHouseholderQr().solve(y);
  EXPECT_GT(std::abs(ols[0] - 2.0), 0.2);
}

TEST(Sindy, TooLittleDataIsAClearError) {
  SpeedPairs d = make_series(-2.66, 4.26, -8.53, 1, 6);
  d.v.conservativeResize(5);
  d.va.conservativeResize(5);
  d.v_next.conservativeResize(5);
  d.va_next.conservativeResize(5);
  EXPECT_THROW(identify_sindy(d, SindyOptions{}), InputError);
  EXPECT_THROW(parse_sindy_method("lasso"), FieldError);
}

}  // namespace
}  // namespace airtwin
