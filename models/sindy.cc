#include "models/sindy.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <random>
#include <thread>
#include <unsupported/Eigen/LevenbergMarquardt>

#include "common/errors.h"
#include "common/parallel_for.h"

namespace airtwin {

const std::array<const char*, kSindyTerms> kTermNames = {
    "1", "v", "vair", "v^2", "v*vair", "vair^2", "v^3", "v^2*vair", "v*vair^2", "vair^3"};

namespace {

constexpr int kV = 1;  // index of the term v
using Coefficients = Eigen::Matrix<double, kSindyTerms, 1>;

Eigen::MatrixXd library(const Eigen::VectorXd& v, const Eigen::VectorXd& va) {
  Eigen::MatrixXd X(v.size(), kSindyTerms);
  for (Eigen::Index i = 0; i < v.size(); ++i) X.row(i) = sindy_library_row(v[i], va[i]);
  return X;
}

// min sum_i w_i (y_i - x_i b)^2 by a pivoted QR of sqrt(W) X b = sqrt(W) y.
Eigen::VectorXd weighted_solve(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                               const Eigen::VectorXd& w) {
  const Eigen::VectorXd sw = w.cwiseSqrt();
  return (sw.asDiagonal() * X).colPivHouseholderQr().solve(sw.cwiseProduct(y));
}

// Least squares on the columns in `active` (others zero), by bisquare IRLS when robust.
// Column-pivoting QR keeps nearly collinear monomials in check.
Coefficients least_squares(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                           const std::vector<int>& active, bool robust, Eigen::VectorXd* w) {
  Eigen::MatrixXd Xa(X.rows(), active.size());
  for (size_t j = 0; j < active.size(); ++j) Xa.col(j) = X.col(active[j]);
  const Eigen::VectorXd b = robust ? bisquare_fit(Xa, y, w) : Xa.colPivHouseholderQr().solve(y);
  if (!robust && w) w->setOnes(X.rows());
  Coefficients xi = Coefficients::Zero();
  for (size_t j = 0; j < active.size(); ++j) xi[active[j]] = b[j];
  return xi;
}

// Sequentially thresholded least squares (Brunton et al. 2016) with lambda on xi_d, removing one
// term per round: the smallest below lambda, then a refit. Removing every sub-lambda term at once
// fails on this library: the monomials of (v, vair) are nearly collinear over the data (vair spans
// only ~1.2-3.3 m/s, the Gram matrix's condition is ~1e8), so the full fit spreads the true vair
// term (0.1065 for the tracer at 40 Hz) over vair^2, vair^3, v*vair, ... and all of them can fall
// under lambda together. Dropping the weakest first lets the others take its share back
// (Boninsegna, Nueske & Clementi 2018, "stepwise sparse regression").
// The fixed point meets STLSQ's condition: every kept |xi_d| >= lambda.
Coefficients stlsq(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, const SindyOptions& o,
                   bool robust, Eigen::VectorXd* w) {
  std::vector<int> active;
  for (int j = 0; j < kSindyTerms; ++j)
    if (o.terms[j]) active.push_back(j);
  Coefficients xi = least_squares(X, y, active, robust, w);
  while (true) {
    auto weakest = active.end();
    for (auto it = active.begin(); it != active.end(); ++it) {
      if (std::abs(xi[*it]) < o.lambda &&
          (weakest == active.end() || std::abs(xi[*it]) < std::abs(xi[*weakest]))) {
        weakest = it;
      }
    }
    if (weakest == active.end()) break;
    active.erase(weakest);
    if (active.empty()) return Coefficients::Zero();
    xi = least_squares(X, y, active, robust, w);
  }
  return xi;
}

double median(std::vector<double> x) {
  AIRTWIN_DEMAND(!x.empty());
  const size_t n = x.size(), m = n / 2;
  std::nth_element(x.begin(), x.begin() + m, x.end());
  if (n % 2) return x[m];
  const double hi = x[m];
  return 0.5 * (hi + *std::max_element(x.begin(), x.begin() + m));
}

// Residuals of the one-step flow for Levenberg-Marquardt over the continuous coefficients of the
// support (the others stay zero).
struct FlowFunctor : Eigen::DenseFunctor<double> {
  const SpeedPairs& d;
  const Eigen::VectorXd& sqrt_w;
  std::vector<int> support;
  FlowFunctor(const SpeedPairs& data, const Eigen::VectorXd& sw, std::vector<int> s)
      : Eigen::DenseFunctor<double>(static_cast<int>(s.size()), static_cast<int>(data.size())),
        d(data),
        sqrt_w(sw),
        support(std::move(s)) {}
  Coefficients expand(const InputType& x) const {
    Coefficients xi = Coefficients::Zero();
    for (size_t j = 0; j < support.size(); ++j) xi[support[j]] = x[j];
    return xi;
  }
  int operator()(const InputType& x, ValueType& f) const {
    const Coefficients xi = expand(x);
    for (size_t k = 0; k < d.size(); ++k) {
      f[k] = sqrt_w[k] * (sindy_flow_step(xi, d.v[k], d.va[k], d.va_next[k], d.dt_s) - d.v_next[k]);
    }
    return 0;
  }
  // Forward differences on the coefficients (the flow is smooth in them).
  int df(const InputType& x, JacobianType& J) const {
    ValueType f0(values()), f1(values());
    (*this)(x, f0);
    for (Eigen::Index j = 0; j < x.size(); ++j) {
      InputType xp = x;
      const double h = 1e-7 * std::max(1.0, std::abs(x[j]));
      xp[j] += h;
      (*this)(xp, f1);
      J.col(j) = (f1 - f0) / h;
    }
    return 0;
  }
};

}  // namespace

Eigen::Matrix<double, 1, kSindyTerms> sindy_library_row(double v, double va) {
  Eigen::Matrix<double, 1, kSindyTerms> r;
  r << 1.0, v, va, v * v, v * va, va * va, v * v * v, v * v * va, v * va * va, va * va * va;
  return r;
}

double sindy_rate(const Coefficients& xi, double v, double va) {
  return sindy_library_row(v, va).dot(xi.transpose());
}

std::array<bool, kSindyTerms> parse_sindy_terms(const std::string& list) {
  std::array<bool, kSindyTerms> mask{};
  std::string known;
  for (const char* name : kTermNames) known += (known.empty() ? "" : ", ") + std::string(name);
  size_t begin = 0;
  while (begin <= list.size()) {
    const size_t end = std::min(list.find(',', begin), list.size());
    const std::string name = list.substr(begin, end - begin);
    const auto it = std::find(kTermNames.begin(), kTermNames.end(), name);
    if (it == kTermNames.end()) {
      throw FieldError("sindy.terms", "unknown term '" + name + "' (the library: " + known + ")");
    }
    bool& used = mask[static_cast<size_t>(it - kTermNames.begin())];
    if (used) throw FieldError("sindy.terms", "'" + name + "' given twice");
    used = true;
    begin = end + 1;
  }
  if (!mask[kV]) {
    throw FieldError(
        "sindy.terms",
        "must include v: it carries the persistence v_{k+1} ~ v_k of the discrete-time "
        "regression (eq. 6)");
  }
  return mask;
}

SindyMethod parse_sindy_method(const std::string& name) {
  if (name == "stlsq") return SindyMethod::kStlsq;
  if (name == "esindy") return SindyMethod::kEsindy;
  if (name == "robust") return SindyMethod::kRobust;
  if (name == "robust-esindy") return SindyMethod::kRobustEsindy;
  throw FieldError("sindy.method",
                   "expected stlsq, esindy, robust or robust-esindy, got '" + name + "'");
}

const char* sindy_method_name(SindyMethod m) {
  switch (m) {
    case SindyMethod::kStlsq:
      return "stlsq";
    case SindyMethod::kEsindy:
      return "esindy";
    case SindyMethod::kRobust:
      return "robust";
    case SindyMethod::kRobustEsindy:
      return "robust-esindy";
  }
  return "?";
}

Eigen::VectorXd bisquare_fit(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                             Eigen::VectorXd* weights_out) {
  const Eigen::Index n = X.rows(), p = X.cols();
  constexpr double kTune = 4.685;
  // Leverages of the unweighted design: squared row norms of the thin Q.
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(X);
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(n, p);
  const Eigen::VectorXd h = Q.rowwise().squaredNorm().cwiseMin(0.9999);
  const Eigen::VectorXd adjust = (1.0 - h.array()).rsqrt().matrix();

  // The iterations solve the weighted normal equations of the column-equilibrated design (p <= 10
  // columns: forming the Gram matrix is several times cheaper than a QR of the n x p matrix); the
  // returned coefficients come from a pivoted QR with the final weights, so the answer keeps
  // the QR's accuracy on this ill-conditioned library.
  const Eigen::VectorXd col_scale = X.colwise().norm().cwiseMax(1e-300).cwiseInverse();
  const Eigen::MatrixXd Xs = X * col_scale.asDiagonal();
  Eigen::VectorXd w = Eigen::VectorXd::Ones(n);
  Eigen::VectorXd b = X.colPivHouseholderQr().solve(y);
  bool reweighted = false;
  std::vector<double> a;  // |adjusted residuals|, reused by every iteration
  for (int it = 0; it < 50; ++it) {
    const Eigen::VectorXd r_adj = (y - X * b).cwiseProduct(adjust);
    // Robust scale: median absolute adjusted residual, ignoring the p smallest (MATLAB madsigma):
    // the order statistics of the tail found by selection, not a full sort (same values).
    a.resize(static_cast<size_t>(n));
    for (Eigen::Index i = 0; i < n; ++i) a[static_cast<size_t>(i)] = std::abs(r_adj[i]);
    const size_t skip = static_cast<size_t>(std::min<Eigen::Index>(p, n - 1));
    const size_t len = a.size() - skip, k = skip + len / 2;
    std::nth_element(a.begin(), a.begin() + static_cast<std::ptrdiff_t>(k), a.end());
    const double hi = a[k];
    const double mid =
        len % 2
            ? hi
            : 0.5 * (hi + *std::max_element(a.begin(), a.begin() + static_cast<std::ptrdiff_t>(k)));
    double s = mid / 0.6745;
    if (!(s > 0)) break;  // an exact fit: nothing to down-weight
    for (Eigen::Index i = 0; i < n; ++i) {
      const double u = r_adj[i] / (kTune * s);
      w[i] = std::abs(u) < 1.0 ? (1 - u * u) * (1 - u * u) : 0.0;
    }
    reweighted = true;
    const Eigen::MatrixXd gram = Xs.transpose() * w.asDiagonal() * Xs;
    const Eigen::VectorXd rhs = Xs.transpose() * w.cwiseProduct(y);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(gram);
    Eigen::VectorXd b_new = col_scale.cwiseProduct(ldlt.solve(rhs));
    if (ldlt.info() != Eigen::Success || !b_new.allFinite()) b_new = weighted_solve(X, y, w);
    const double change = (b_new - b).cwiseAbs().maxCoeff();
    const double scale = std::max(b_new.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff());
    b = b_new;
    if (change <= 1.5e-8 * scale) break;  // sqrt(eps), as robustfit
  }
  if (reweighted) b = weighted_solve(X, y, w);
  if (weights_out) *weights_out = w;
  return b;
}

double sindy_flow_step(const Coefficients& xi, double v0, double va0, double va1, double dt_s,
                       int substeps) {
  const double h = dt_s / substeps;
  double v = v0;
  for (int i = 0; i < substeps; ++i) {
    const double s0 = static_cast<double>(i) / substeps, s1 = static_cast<double>(i + 1) / substeps;
    const double a0 = va0 + (va1 - va0) * s0, a1 = va0 + (va1 - va0) * s1, am = 0.5 * (a0 + a1);
    const double k1 = sindy_rate(xi, v, a0);
    const double k2 = sindy_rate(xi, v + 0.5 * h * k1, am);
    const double k3 = sindy_rate(xi, v + 0.5 * h * k2, am);
    const double k4 = sindy_rate(xi, v + h * k3, a1);
    v += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return v;
}

SindyResult identify_sindy(const SpeedPairs& d, const SindyOptions& o) {
  const Eigen::Index n = d.v.size();
  if (d.va.size() != n || d.v_next.size() != n || d.va_next.size() != n) {
    throw InputError("identification: speed series of unequal lengths");
  }
  if (n < 2 * kSindyTerms) {
    throw InputError("identification: " + std::to_string(n) + " usable speed pairs, at least " +
                     std::to_string(2 * kSindyTerms) + " are needed for " +
                     std::to_string(kSindyTerms) + " library terms");
  }
  if (!(d.v.allFinite() && d.va.allFinite() && d.v_next.allFinite() && d.va_next.allFinite()) ||
      !(d.dt_s > 0)) {
    throw InputError("identification: speed series contain non-finite values or dt <= 0");
  }
  if (!(o.lambda >= 0) || o.bootstraps < 1) {
    throw FieldError("sindy.lambda, sindy.bootstraps", "expected lambda >= 0 and bootstraps >= 1");
  }
  const bool robust = o.method == SindyMethod::kRobust || o.method == SindyMethod::kRobustEsindy;
  const bool ensemble = o.method == SindyMethod::kEsindy || o.method == SindyMethod::kRobustEsindy;
  const Eigen::MatrixXd X = library(d.v, d.va);

  SindyResult res;
  res.weights = Eigen::VectorXd::Ones(n);
  if (!ensemble) {
    res.discrete = stlsq(X, d.v_next, o, robust, &res.weights);
    for (int j = 0; j < kSindyTerms; ++j) res.inclusion[j] = res.discrete[j] != 0.0 ? 1.0 : 0.0;
  } else {
    // E-SINDy: bootstrap the rows, identify each, take the median per term.
    // The rows of every bootstrap drawn first, in order, then the fits in parallel.
    std::mt19937_64 rng(o.seed);
    std::uniform_int_distribution<Eigen::Index> pick(0, n - 1);
    const size_t nb = static_cast<size_t>(o.bootstraps);
    std::vector<std::vector<Eigen::Index>> rows(nb, std::vector<Eigen::Index>(n));
    for (std::vector<Eigen::Index>& r : rows)
      for (Eigen::Index& k : r) k = pick(rng);
    std::vector<Coefficients> fits(nb);
    const int threads = o.threads > 0
                            ? o.threads
                            : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    parallel_for(nb, threads, [&](size_t b) {
      Eigen::MatrixXd Xb(n, kSindyTerms);
      Eigen::VectorXd yb(n);
      for (Eigen::Index i = 0; i < n; ++i) {
        const Eigen::Index k = rows[b][static_cast<size_t>(i)];
        Xb.row(i) = X.row(k);
        yb[i] = d.v_next[k];
      }
      fits[b] = stlsq(Xb, yb, o, robust, nullptr);
    });
    std::vector<std::vector<double>> samples(kSindyTerms);
    for (const Coefficients& xi : fits)
      for (int j = 0; j < kSindyTerms; ++j) samples[j].push_back(xi[j]);
    for (int j = 0; j < kSindyTerms; ++j) {
      res.discrete[j] = median(samples[j]);
      res.inclusion[j] =
          std::count_if(samples[j].begin(), samples[j].end(), [](double x) { return x != 0.0; }) /
          static_cast<double>(o.bootstraps);
    }
    // Robust weights of the ensemble's model on the whole data set, for the conversion below.
    if (robust) {
      std::vector<int> active;
      for (int j = 0; j < kSindyTerms; ++j)
        if (res.discrete[j] != 0.0) active.push_back(j);
      if (!active.empty()) least_squares(X, d.v_next, active, true, &res.weights);
    }
  }

  // Continuous time: forward-difference reading as the start, then exact one-step flow matching.
  std::vector<int> support;
  for (int j = 0; j < kSindyTerms; ++j)
    if (res.discrete[j] != 0.0 || j == kV) support.push_back(j);
  Coefficients start = res.discrete;
  start[kV] -= 1.0;
  start /= d.dt_s;
  const Eigen::VectorXd sqrt_w = res.weights.cwiseSqrt();
  FlowFunctor functor(d, sqrt_w, support);
  Eigen::VectorXd x(support.size());
  for (size_t j = 0; j < support.size(); ++j) x[j] = start[support[j]];
  Eigen::LevenbergMarquardt<FlowFunctor> lm(functor);
  lm.setXtol(1e-12);
  lm.setFtol(1e-14);
  lm.setMaxfev(400);
  lm.minimize(x);
  res.continuous = x.allFinite() ? functor.expand(x) : start;

  // R^2 of v_{k+1} (the regression's target, the paper's figure) and of the one-step change,
  // both from the continuous model's one-step flow, over all pairs.
  double ss_res = 0, ss_change = 0, ss_next = 0;
  const double mean_change = (d.v_next - d.v).mean(), mean_next = d.v_next.mean();
  for (Eigen::Index k = 0; k < n; ++k) {
    const double next = sindy_flow_step(res.continuous, d.v[k], d.va[k], d.va_next[k], d.dt_s);
    const double dv = d.v_next[k] - d.v[k];
    ss_res += (d.v_next[k] - next) * (d.v_next[k] - next);
    ss_change += (dv - mean_change) * (dv - mean_change);
    ss_next += (d.v_next[k] - mean_next) * (d.v_next[k] - mean_next);
  }
  res.r2 = ss_next > 0 ? 1.0 - ss_res / ss_next : 0.0;
  res.r2_change = ss_change > 0 ? 1.0 - ss_res / ss_change : 0.0;
  return res;
}

}  // namespace airtwin
