#pragma once
// Sparse identification of the object speed dynamics (section IV-A, eqs. 5-7).
//
// The data are pairs of consecutive speed samples (v_k, v_{k+1}) with the air speed at the
// object (va_k, va_{k+1}), dt apart. The library Theta(v, va) holds the constant and every
// monomial of (v, va) up to degree 3, ten terms in the order of kTermNames. The regression is in
// discrete time, as the paper does (eq. 6): target v_{k+1}, regressors Theta(v_k, va_k),
// sequentially thresholded least squares with lambda applied to the discrete coefficients (at
// 40 Hz they are dt times the continuous ones, so lambda = 0.07 keeps the tracer's true terms),
// one term removed per round (the weakest under lambda; see sindy.cc for why).
// Options: E-SINDy (bootstraps of the rows, median of the coefficients, inclusion probabilities)
// and bisquare-weighted IRLS for every least-squares solve (MATLAB robustfit's definition).
//
// Conversion to continuous time: the forward-difference reading xi_c = (xi_d - e_v) / dt is off
// by ~3% at 40 Hz for xi1 = -2.66 (exp(xi1 dt) against 1 + xi1 dt). We therefore use it only as the
// starting point and then match the model's exact one-step flow to the data on the selected
// support: v_{k+1} = Phi_dt(v_k; xi_c) with va linear in time across the step, Phi by RK4 with
// 8 sub-steps, solved by Levenberg-Marquardt (Eigen), weighted by the robust weights.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace airtwin {

constexpr int kSindyTerms = 10;
extern const std::array<const char*, kSindyTerms> kTermNames;  // "1", "v", "vair", "v^2", ...
/// Where eq. (8)'s three terms sit in kTermNames: dv/dt = xi3 + xi1 v + xi2 vair.
inline constexpr int kTermConstant = 0, kTermV = 1, kTermVair = 2;

/// The library row Theta(v, va).
Eigen::Matrix<double, 1, kSindyTerms> sindy_library_row(double v, double va);
/// dv/dt of the continuous model with coefficients xi at (v, va).
double sindy_rate(const Eigen::Matrix<double, kSindyTerms, 1>& xi, double v, double va);

/// Consecutive speed pairs for regression. All vectors have the same length.
struct SpeedPairs {
  Eigen::VectorXd v, va, v_next, va_next;
  double dt_s = 0.025;
  size_t size() const { return static_cast<size_t>(v.size()); }
};

enum class SindyMethod { kStlsq, kEsindy, kRobust, kRobustEsindy };
/// "stlsq" | "esindy" | "robust" | "robust-esindy"; throws FieldError (sindy.method) otherwise.
SindyMethod parse_sindy_method(const std::string& name);
const char* sindy_method_name(SindyMethod m);

/// Library terms by name ("1,v,vair"): a mask over kTermNames. Throws FieldError (sindy.terms)
/// naming an unknown or repeated term, or a list without "v" (in discrete time v carries the
/// persistence v_{k+1} ~ v_k of eq. 6, so no model is possible without it).
std::array<bool, kSindyTerms> parse_sindy_terms(const std::string& list);

/// How the regressions are computed; both give the same model to rounding (discrete coefficients
/// within 1e-6; tests/models/sindy_test.cc, bench/identify_bench.cc).
/// kFast: a bootstrap is its distinct rows with their multiplicities as weights (no copied rows);
///   each stepwise refit's IRLS starts from the weights the previous refit ended with; leverages
///   from the triangular factor of a QR; the weighted normal equations by a tiled kernel; the
///   scale's order statistics selected near the last one; the one-step flow for the
///   continuous-time fit evaluated over all pairs at once with the rate as a polynomial in v.
/// kReference: MATLAB robustfit's iteration literally, as bisquare_fit: every refit from ordinary
///   least squares on the bootstrap's copied rows, leverages from the explicit Q, the flow by
///   sindy_flow_step pair by pair. About 3-4 times slower; kept to check kFast against.
enum class SindySolver { kFast, kReference };

struct SindyOptions {
  SindyMethod method = SindyMethod::kRobustEsindy;
  SindySolver solver = SindySolver::kFast;
  /// The library terms the regression may use (all by default). Fewer: prior knowledge of the
  /// structure, e.g. {1, v, vair} for eq. (8) when the data cannot tell structures apart.
  std::array<bool, kSindyTerms> terms = {true, true, true, true, true,
                                         true, true, true, true, true};
  double lambda = 0.07;  ///< threshold on discrete-time coefficients
  int bootstraps = 15;
  std::uint64_t seed = 1;
  /// Bootstraps fitted in parallel (0: one thread per core). The rows of every bootstrap are drawn
  /// first, in order, from `seed`: the result does not depend on the thread count.
  int threads = 0;
};

struct SindyResult {
  Eigen::Matrix<double, kSindyTerms, 1> discrete;    ///< xi_d (E-SINDy: the median)
  Eigen::Matrix<double, kSindyTerms, 1> continuous;  ///< xi_c, 1/s scale (dv/dt)
  Eigen::Matrix<double, kSindyTerms, 1> inclusion;   ///< fraction of bootstraps keeping a term
  /// Goodness of fit of the regression of eq. (6), as the paper reports it: R^2 of the target
  /// v_{k+1} predicted by the continuous model's one-step flow from v_k, all pairs.
  double r2 = 0.0;
  /// A stricter figure: R^2 of the one-step change v_{k+1} - v_k (the part the model explains
  /// beyond persistence), same predictions.
  double r2_change = 0.0;
  Eigen::VectorXd weights;  ///< final robust weights per pair (1 without robust regression)
};

/// Identifies the model. Throws InputError when there are fewer pairs than twice the library size
/// or the data are not finite.
SindyResult identify_sindy(const SpeedPairs& data, const SindyOptions& options);

/// Bisquare IRLS (MATLAB robustfit: tuning 4.685, residuals adjusted by leverage sqrt(1 - h),
/// scale MAD / 0.6745 of the adjusted residuals ignoring the p smallest). Returns coefficients;
/// `weights_out` (optional) receives the final weights.
Eigen::VectorXd bisquare_fit(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                             Eigen::VectorXd* weights_out = nullptr);

/// One step of the continuous model from v0 over dt with va linear from va0 to va1 (RK4).
double sindy_flow_step(const Eigen::Matrix<double, kSindyTerms, 1>& xi, double v0, double va0,
                       double va1, double dt_s, int substeps = 8);

}  // namespace airtwin
