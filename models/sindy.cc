#include "models/sindy.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <random>
#include <thread>
#include <unsupported/Eigen/LevenbergMarquardt>
#include <utility>

#include "common/errors.h"
#include "common/parallel_for.h"

namespace airtwin {

const std::array<const char*, kSindyTerms> kTermNames = {
    "1", "v", "vair", "v^2", "v*vair", "vair^2", "v^3", "v^2*vair", "v*vair^2", "vair^3"};

namespace {

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

// Sequentially thresholded least squares (Brunton et al. 2016) with lambda on xi_d, removing one
// term per round: the smallest below lambda, then a refit. Removing every sub-lambda term at once
// fails on this library: the monomials of (v, vair) are nearly collinear over the data (vair spans
// only ~1.2-3.3 m/s, the Gram matrix's condition is ~1e8), so the full fit spreads the true vair
// term (0.1065 for the tracer at 40 Hz) over vair^2, vair^3, v*vair, ... and all of them can fall
// under lambda together. Dropping the weakest first lets the others take its share back
// (Boninsegna, Nueske & Clementi 2018, "stepwise sparse regression").
// The fixed point meets STLSQ's condition: every kept |xi_d| >= lambda.
// `refit(active)` returns the least-squares coefficients on the columns in `active`.
template <class Refit>
Coefficients stlsq(const SindyOptions& o, Refit&& refit) {
  std::vector<int> active;
  for (int j = 0; j < kSindyTerms; ++j)
    if (o.terms[j]) active.push_back(j);
  Coefficients xi = refit(active);
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
    xi = refit(active);
  }
  return xi;
}

// ---- SindySolver::kFast

// The regression data of the fast path: the distinct rows of the design with their multiplicities
// (a bootstrap's draw counts; 1 for the data themselves). Weighted by the multiplicities, every
// sum over them equals the sum over the copied rows, so the fits are those of the copied rows.
// The columns are scaled to unit norm (over the multiplicities): the normal equations of any
// active set are then equilibrated.
struct CountedRows {
  Eigen::MatrixXd Xs;      // m x kSindyTerms, columns scaled: Xs = X diag(col_scale)
  Coefficients col_scale;  // coefficients of X = col_scale .* coefficients of Xs
  Eigen::VectorXd y, count, sqrt_count;
  double total = 0;  // sum of the multiplicities: the number of rows they stand for

  // Rows of X and y with multiplicity count[i] > 0, in order.
  CountedRows(const Eigen::MatrixXd& X, const Eigen::VectorXd& yall,
              const std::vector<int>& counts) {
    Eigen::Index m = 0;
    for (int c : counts) m += c > 0;
    Xs.resize(m, kSindyTerms);
    y.resize(m);
    count.resize(m);
    Eigen::Index r = 0;
    for (size_t i = 0; i < counts.size(); ++i) {
      if (counts[i] == 0) continue;
      const Eigen::Index k = static_cast<Eigen::Index>(i);
      Xs.row(r) = X.row(k);
      y[r] = yall[k];
      count[r] = counts[i];
      ++r;
    }
    total = count.sum();
    sqrt_count = count.cwiseSqrt();
    for (int j = 0; j < kSindyTerms; ++j) {
      col_scale[j] = 1.0 / std::max(std::sqrt(count.dot(Xs.col(j).cwiseAbs2())), 1e-300);
      Xs.col(j) *= col_scale[j];
    }
  }
};

// The k-th smallest (0-based) of the values in [first, last) taken each with its multiplicity,
// and the (k-1)-th (k >= 1): quickselect on (value, multiplicity) pairs, which it reorders.
using CountedValue = std::pair<double, double>;
std::pair<double, double> counted_order_statistics(CountedValue* first, CountedValue* last,
                                                   double k) {
  using It = CountedValue*;
  It lo = first, hi = last;
  while (true) {
    const double x = lo->first, y = (lo + (hi - lo) / 2)->first, z = (hi - 1)->first;
    const double pivot = std::max(std::min(x, y), std::min(std::max(x, y), z));
    const It less_end = std::partition(lo, hi, [&](const auto& e) { return e.first < pivot; });
    const It equal_end =
        std::partition(less_end, hi, [&](const auto& e) { return !(pivot < e.first); });
    double below = 0, equal = 0;
    for (It e = lo; e != less_end; ++e) below += e->second;
    for (It e = less_end; e != equal_end; ++e) equal += e->second;
    if (k < below) {
      hi = less_end;
    } else if (k < below + equal) {
      // Every value left of less_end is below the pivot, every value right of equal_end above.
      double previous = pivot;
      if (k - 1 < below) {
        previous = first->first;
        for (It e = first; e != less_end; ++e) previous = std::max(previous, e->first);
      }
      return {pivot, previous};
    } else {
      k -= below + equal;
      lo = equal_end;
    }
  }
}

// The lower triangle of A^T diag(c) A for an n x q column-major A (q <= kSindyTerms + 1), into
// the q x q column-major `out`: with the target as A's last column, the weighted normal equations
// and their right-hand side (the last row) at once. 2 x 2 tiles of weighted column dot products,
// four rows at a time (GCC/Clang vector extension): a tile loads five columns for four products
// where one dot product at a time loads three for one, and the weighted A is never stored; these
// sums are most of an IRLS iteration's time. Compiled for AVX2 CPUs (x86-64-v3) and for baseline
// x86-64 like the field kernel, picked at load time; models/ builds with -ffp-contract=off and the
// lanes are fixed by the vector type, so both compute the same IEEE operations.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(AIRTWIN_NO_TARGET_CLONES)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void lower_weighted_gram(const double* A, Eigen::Index n, Eigen::Index q, const double* c,
                         double* out) {
  using Quad = double __attribute__((vector_size(32), aligned(8), may_alias));
  const Eigen::Index body = n & ~Eigen::Index{3};
  for (Eigen::Index j = 0; j < q; j += 2) {
    const bool j2 = j + 1 < q;
    const double *a0 = A + j * n, *a1 = j2 ? a0 + n : a0;
    for (Eigen::Index k = 0; k <= j; k += 2) {
      const bool k2 = k + 1 < q;
      const double *b0 = A + k * n, *b1 = k2 ? b0 + n : b0;
      Quad s00 = {0, 0, 0, 0}, s01 = s00, s10 = s00, s11 = s00;
      for (Eigen::Index i = 0; i < body; i += 4) {
        const Quad w = *reinterpret_cast<const Quad*>(c + i);
        const Quad x0 = w * *reinterpret_cast<const Quad*>(a0 + i),
                   x1 = w * *reinterpret_cast<const Quad*>(a1 + i);
        const Quad y0 = *reinterpret_cast<const Quad*>(b0 + i),
                   y1 = *reinterpret_cast<const Quad*>(b1 + i);
        s00 += x0 * y0;
        s01 += x0 * y1;
        s10 += x1 * y0;
        s11 += x1 * y1;
      }
      double t00 = (s00[0] + s00[1]) + (s00[2] + s00[3]),
             t01 = (s01[0] + s01[1]) + (s01[2] + s01[3]),
             t10 = (s10[0] + s10[1]) + (s10[2] + s10[3]),
             t11 = (s11[0] + s11[1]) + (s11[2] + s11[3]);
      for (Eigen::Index i = body; i < n; ++i) {
        t00 += c[i] * a0[i] * b0[i];
        t01 += c[i] * a0[i] * b1[i];
        t10 += c[i] * a1[i] * b0[i];
        t11 += c[i] * a1[i] * b1[i];
      }
      out[j + k * q] = t00;
      if (k + 1 <= j) out[j + (k + 1) * q] = t01;
      if (j2) out[j + 1 + k * q] = t10;
      if (j2 && k2) out[j + 1 + (k + 1) * q] = t11;
    }
  }
}

// Least squares on a set of active columns of CountedRows, by bisquare IRLS when robust: the
// iteration of bisquare_fit (same scale, weights and convergence test) on the distinct rows.
// Successive calls (the stepwise refits of one data set) start their IRLS from the weights the
// previous call ended with instead of from ordinary least squares: the active set lost one weak
// term, so those weights are close to the new fixed point and fewer iterations reach it.
class CountedFit {
 public:
  CountedFit(const CountedRows& rows, bool robust) : rows_(rows), robust_(robust) {}

  Coefficients operator()(const std::vector<int>& active) {
    const Eigen::Index m = rows_.Xs.rows(), p = static_cast<Eigen::Index>(active.size());
    Xa_.resize(m, p + 1);  // the active columns, then the target
    Xa_.col(p) = rows_.y;
    Coefficients scale_a;
    for (Eigen::Index j = 0; j < p; ++j) {
      Xa_.col(j) = rows_.Xs.col(active[static_cast<size_t>(j)]);
      scale_a[j] = rows_.col_scale[active[static_cast<size_t>(j)]];
    }
    const Eigen::VectorXd bs = robust_ ? irls(p, scale_a.head(p)) : weighted_qr(rows_.count);
    Coefficients xi = Coefficients::Zero();
    for (Eigen::Index j = 0; j < p; ++j) xi[active[static_cast<size_t>(j)]] = scale_a[j] * bs[j];
    return xi;
  }

  /// Final weights per distinct row (ones without robust regression or before any fit).
  Eigen::VectorXd weights() const {
    return w_.size() ? w_ : Eigen::VectorXd::Ones(rows_.Xs.rows());
  }

 private:
  using Small =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kSindyTerms + 1, kSindyTerms + 1>;

  // The active columns of the design (Xa_ ends with the target).
  auto design() const { return Xa_.leftCols(Xa_.cols() - 1); }

  // min sum_i c_i w_i (y_i - x_i b)^2 by a pivoted QR (scaled coordinates).
  Eigen::VectorXd weighted_qr(const Eigen::VectorXd& cw) const {
    const Eigen::VectorXd s = cw.cwiseSqrt();
    return (s.asDiagonal() * design()).colPivHouseholderQr().solve(s.cwiseProduct(rows_.y));
  }

  Eigen::VectorXd irls(Eigen::Index p, const Eigen::Ref<const Eigen::VectorXd>& scale_a) {
    const Eigen::Index m = Xa_.rows();
    constexpr double kTune = 4.685;
    // Leverages of the (multiplicity-weighted) design, h_i = x_i (R^T R)^-1 x_i^T = |x_i R^-1|^2
    // with R from a QR of sqrt(c) Xa; the same QR gives the ordinary least-squares start.
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(rows_.sqrt_count.asDiagonal() * design());
    Eigen::MatrixXd Z = design();
    qr.matrixQR().topRows(p).triangularView<Eigen::Upper>().solveInPlace<Eigen::OnTheRight>(Z);
    Eigen::VectorXd h = Z.rowwise().squaredNorm();
    if (!h.allFinite()) {  // a singular R: the squared row norms of the thin Q instead
      const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(m, p);
      h = Q.rowwise().squaredNorm().cwiseQuotient(rows_.count);
    }
    adjust_ = (1.0 - h.cwiseMin(0.9999).array()).rsqrt().matrix();

    Eigen::VectorXd bs;  // scaled coordinates
    if (w_.size() == m) {
      bs = normal_solve(p, rows_.count.cwiseProduct(w_));  // warm start: the last fit's weights
    } else {
      bs = qr.solve(rows_.sqrt_count.cwiseProduct(rows_.y));
      w_.setOnes(m);
    }
    Eigen::VectorXd b = scale_a.cwiseProduct(bs);
    bool reweighted = false;
    for (int it = 0; it < 50; ++it) {
      r_adj_.noalias() = rows_.y - design() * bs;
      r_adj_.array() *= adjust_.array();
      // Robust scale (MATLAB madsigma): the median absolute adjusted residual of the copied rows,
      // ignoring the p smallest.
      const double skip = std::min(static_cast<double>(p), rows_.total - 1);
      const double len = rows_.total - skip, k = skip + std::floor(len / 2);
      const auto [hi, below] = abs_residual_order_statistics(k);
      const double mid = std::fmod(len, 2.0) != 0 ? hi : 0.5 * (hi + below);
      const double s = mid / 0.6745;
      if (!(s > 0)) break;  // an exact fit: nothing to down-weight
      const double inv = 1.0 / (kTune * s);
      for (Eigen::Index i = 0; i < m; ++i) {
        const double u = r_adj_[i] * inv;
        w_[i] = std::abs(u) < 1.0 ? (1 - u * u) * (1 - u * u) : 0.0;
      }
      reweighted = true;
      const Eigen::VectorXd bs_new = normal_solve(p, rows_.count.cwiseProduct(w_));
      const Eigen::VectorXd b_new = scale_a.cwiseProduct(bs_new);
      const double change = (b_new - b).cwiseAbs().maxCoeff();
      const double scale = std::max(b_new.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff());
      b = b_new;
      bs = bs_new;
      if (change <= 1.5e-8 * scale) break;  // sqrt(eps), as robustfit
    }
    if (reweighted) bs = weighted_qr(rows_.count.cwiseProduct(w_));
    return bs;
  }

  // The k-th and (k-1)-th smallest |r_adj_| of the copied rows (k >= 1). The scale moves little
  // from one iteration to the next: one pass counts the rows below +-5 % around the last k-th
  // value and gathers those inside, and when both ranks fall inside they are selected among those
  // few; otherwise (a first iteration, a larger move) quickselect on every row.
  std::pair<double, double> abs_residual_order_statistics(double k) {
    const Eigen::Index m = r_adj_.size();
    sel_.resize(static_cast<size_t>(m));
    CountedValue* out = sel_.data();
    if (last_ > 0) {
      // Branch-free: every value is written and the end advances over those inside.
      const double lo = 0.95 * last_, hi = 1.05 * last_;
      const double *r = r_adj_.data(), *count = rows_.count.data();
      double below = 0;
      for (Eigen::Index i = 0; i < m; ++i) {
        const double a = std::abs(r[i]);
        below += a < lo ? count[i] : 0.0;
        *out = {a, count[i]};
        out += a >= lo && a <= hi;
      }
      double inside = 0;
      for (const CountedValue* e = sel_.data(); e != out; ++e) inside += e->second;
      if (below <= k - 1 && k < below + inside) {
        const auto r = counted_order_statistics(sel_.data(), out, k - below);
        last_ = r.first;
        return r;
      }
      out = sel_.data();
    }
    for (Eigen::Index i = 0; i < m; ++i) *out++ = {std::abs(r_adj_[i]), rows_.count[i]};
    const auto r = counted_order_statistics(sel_.data(), out, k);
    last_ = r.first;
    return r;
  }

  // The weighted normal equations (Xa^T C Xa) bs = Xa^T C y, C = diag(cw), of the equilibrated
  // columns by LDLT (as bisquare_fit); a pivoted QR if singular.
  Eigen::VectorXd normal_solve(Eigen::Index p, const Eigen::VectorXd& cw) {
    Small gram(p + 1, p + 1);
    lower_weighted_gram(Xa_.data(), Xa_.rows(), p + 1, cw.data(), gram.data());
    const Eigen::LDLT<Small, Eigen::Lower> ldlt(gram.topLeftCorner(p, p));
    Eigen::VectorXd bs = ldlt.solve(gram.row(p).head(p).transpose());
    if (ldlt.info() != Eigen::Success || !bs.allFinite()) bs = weighted_qr(cw);
    return bs;
  }

  const CountedRows& rows_;
  bool robust_;
  Eigen::MatrixXd Xa_;
  Eigen::VectorXd w_, adjust_, r_adj_;
  std::vector<CountedValue> sel_;
  double last_ = 0;  // the last k-th smallest |r_adj_|
};

// ---- SindySolver::kReference

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

double median(std::vector<double> x) {
  AIRTWIN_DEMAND(!x.empty());
  const size_t n = x.size(), m = n / 2;
  std::nth_element(x.begin(), x.begin() + m, x.end());
  if (n % 2) return x[m];
  const double hi = x[m];
  return 0.5 * (hi + *std::max_element(x.begin(), x.begin() + m));
}

// The one-step flow of every pair at once: sindy_flow_step's RK4 (8 sub-steps, va linear in time)
// with the rate as a cubic in v whose coefficients are polynomials in va, sub-step by sub-step
// over all pairs (a loop the compiler vectorises; compiled for AVX2 CPUs and baseline x86-64 as
// lower_weighted_gram, the same IEEE operations).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(AIRTWIN_NO_TARGET_CLONES)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void flow_steps(const Coefficients& xi, const SpeedPairs& d, Eigen::VectorXd& next) {
  constexpr int kSubsteps = 8;
  const Eigen::Index n = d.v.size();
  const double h = d.dt_s / kSubsteps;
  next = d.v;
  double* v = next.data();
  const double *va0 = d.va.data(), *va1 = d.va_next.data();
  const auto rate = [&xi](double x, double a) {
    const double c0 = xi[0] + a * (xi[2] + a * (xi[5] + a * xi[9]));
    const double c1 = xi[1] + a * (xi[4] + a * xi[8]);
    const double c2 = xi[3] + a * xi[7];
    return c0 + x * (c1 + x * (c2 + x * xi[6]));
  };
  for (int i = 0; i < kSubsteps; ++i) {
    const double s0 = static_cast<double>(i) / kSubsteps,
                 s1 = static_cast<double>(i + 1) / kSubsteps;
    for (Eigen::Index k = 0; k < n; ++k) {
      const double a0 = va0[k] + (va1[k] - va0[k]) * s0, a1 = va0[k] + (va1[k] - va0[k]) * s1,
                   am = 0.5 * (a0 + a1);
      const double k1 = rate(v[k], a0);
      const double k2 = rate(v[k] + 0.5 * h * k1, am);
      const double k3 = rate(v[k] + 0.5 * h * k2, am);
      const double k4 = rate(v[k] + h * k3, a1);
      v[k] += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
  }
}

// The one-step flow of every pair by the solver's evaluation: flow_steps (kFast) or
// sindy_flow_step pair by pair (kReference).
void flow_all(const Coefficients& xi, const SpeedPairs& d, SindySolver solver,
              Eigen::VectorXd& next) {
  if (solver == SindySolver::kFast) return flow_steps(xi, d, next);
  next.resize(d.v.size());
  for (size_t k = 0; k < d.size(); ++k)
    next[k] = sindy_flow_step(xi, d.v[k], d.va[k], d.va_next[k], d.dt_s);
}

// Residuals of the one-step flow for Levenberg-Marquardt over the continuous coefficients of the
// support (the others stay zero).
struct FlowFunctor : Eigen::DenseFunctor<double> {
  const SpeedPairs& d;
  const Eigen::VectorXd& sqrt_w;
  std::vector<int> support;
  SindySolver solver;
  FlowFunctor(const SpeedPairs& data, const Eigen::VectorXd& sw, std::vector<int> s, SindySolver sv)
      : Eigen::DenseFunctor<double>(static_cast<int>(s.size()), static_cast<int>(data.size())),
        d(data),
        sqrt_w(sw),
        support(std::move(s)),
        solver(sv) {}
  Coefficients expand(const InputType& x) const {
    Coefficients xi = Coefficients::Zero();
    for (size_t j = 0; j < support.size(); ++j) xi[support[j]] = x[j];
    return xi;
  }
  int operator()(const InputType& x, ValueType& f) const {
    Eigen::VectorXd next;
    flow_all(expand(x), d, solver, next);
    f = sqrt_w.cwiseProduct(next - d.v_next);
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
  if (!mask[kTermV]) {
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

  const bool fast = o.solver == SindySolver::kFast;
  const std::vector<int> once(static_cast<size_t>(n), 1);

  SindyResult res;
  res.weights = Eigen::VectorXd::Ones(n);
  if (!ensemble) {
    if (fast) {
      const CountedRows rows(X, d.v_next, once);
      CountedFit fit(rows, robust);
      res.discrete = stlsq(o, fit);
      res.weights = fit.weights();
    } else {
      res.discrete = stlsq(o, [&](const std::vector<int>& active) {
        return least_squares(X, d.v_next, active, robust, &res.weights);
      });
    }
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
      if (fast) {
        std::vector<int> counts(static_cast<size_t>(n), 0);
        for (Eigen::Index k : rows[b]) ++counts[static_cast<size_t>(k)];
        const CountedRows sample(X, d.v_next, counts);
        fits[b] = stlsq(o, CountedFit(sample, robust));
        return;
      }
      Eigen::MatrixXd Xb(n, kSindyTerms);
      Eigen::VectorXd yb(n);
      for (Eigen::Index i = 0; i < n; ++i) {
        const Eigen::Index k = rows[b][static_cast<size_t>(i)];
        Xb.row(i) = X.row(k);
        yb[i] = d.v_next[k];
      }
      fits[b] = stlsq(o, [&](const std::vector<int>& active) {
        return least_squares(Xb, yb, active, robust, nullptr);
      });
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
      if (!active.empty() && fast) {
        const CountedRows all(X, d.v_next, once);
        CountedFit fit(all, true);
        fit(active);
        res.weights = fit.weights();
      } else if (!active.empty()) {
        least_squares(X, d.v_next, active, true, &res.weights);
      }
    }
  }

  // Continuous time: forward-difference reading as the start, then exact one-step flow matching.
  std::vector<int> support;
  for (int j = 0; j < kSindyTerms; ++j)
    if (res.discrete[j] != 0.0 || j == kTermV) support.push_back(j);
  Coefficients start = res.discrete;
  start[kTermV] -= 1.0;
  start /= d.dt_s;
  const Eigen::VectorXd sqrt_w = res.weights.cwiseSqrt();
  FlowFunctor functor(d, sqrt_w, support, o.solver);
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
  Eigen::VectorXd flow;
  flow_all(res.continuous, d, o.solver, flow);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double next = flow[k];
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
