#include "models/field_fit.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <future>
#include <limits>
#include <map>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <unsupported/Eigen/LevenbergMarquardt>

#include "common/errors.h"
#include "common/units.h"
#include "models/air_field.h"

namespace airtwin {
namespace {

constexpr int kBins = FieldTable::kAlphaBins;
constexpr int kParams = 3 * kBins;  // x[3 k + j] is parameter theta_j of bin k (see from_theta)
using Ring = std::array<FieldCoefficients, kBins>;

// A sample in its jet's frame, with its fit weight.
struct JetPoint {
  double r = 0.0;       // m from s
  int bin = 0;          // alpha lies in [bin, bin + 1) deg ...
  double frac = 0.0;    // ... at bin + frac
  double speed = 0.0;   // data, m/s
  double weight = 0.0;  // w_i of the cost
};

// The samples of one tilt, by source.
struct TiltSamples {
  double tilt_rad = 0.0;
  std::string sources;  // the file names, for messages
  std::vector<const FieldSample*> grid, cfd;
};

// Weight of the anchor rows in units of the per-bin data scale: far too weak to bias a fit the
// data determine, enough to make every parameter determined (a full-rank Jacobian).
constexpr double kAnchorRatio = 1e-4;
// Coefficients beyond this magnitude mean a diverged fit.
constexpr double kMaxCoefficient = 1e9;
// Distinct tilts must be at least this far apart (deg).
constexpr double kMinTiltSpacingDeg = 0.1;

std::string tilt_text(double tilt_rad) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", rad_to_deg(tilt_rad));
  return buf;
}

// e^x with the argument capped, so that a trial step of the optimiser far off the data cannot
// overflow.
double capped_exp(double x) { return std::exp(std::min(x, 700.0)); }

// eq. (3) and its partial derivatives d v / d (b1, b2, b3) at distance r.
struct ProfileValue {
  double v;
  std::array<double, 3> dv;
};
ProfileValue eval_profile(const FieldCoefficients& c, double r) {
  const double e2 = capped_exp(c.b2 * r), e3 = capped_exp(c.b3 * r);
  return {c.b1 * (e2 - e3), {e2 - e3, c.b1 * r * e2, -c.b1 * r * e3}};
}

// The largest gap b2 - b3 (1/m) a profile may have: a rise from zero at s to the peak within
// ~1 mm, finer than any data resolves. Without samples near s (a measured grid alone) the data
// cannot bound b3, and the fit would otherwise carry it toward -infinity.
constexpr double kMaxGap = 1000.0;

// The fitted parameters of one profile: theta = (ln b1, ln(-b2), logit((b2 - b3) / kMaxGap)).
// Every theta is a profile on the physical branch b1 > 0, b3 < b2 < 0 (a speed that rises from
// zero at s, peaks and decays), so the sign ambiguity b1 (e^{b2 r} - e^{b3 r}) =
// -b1 (e^{b3 r} - e^{b2 r}) never arises; a step in theta is a relative change of b1, b2 and
// (well below kMaxGap) of the gap b2 - b3.
FieldCoefficients from_theta(const double* t) {
  const double b2 = -capped_exp(t[1]);
  return {capped_exp(t[0]), b2, b2 - kMaxGap / (1.0 + capped_exp(-t[2]))};
}
std::array<double, 3> to_theta(const FieldCoefficients& c) {
  const double gap = std::clamp(c.b2 - c.b3, 1e-12, 0.999 * kMaxGap);
  return {std::log(c.b1), std::log(-c.b2), -std::log(kMaxGap / gap - 1.0)};
}
// d v / d theta of one profile from d v / d b: b1 = e^t1; b2 = -e^t2 moves b3 with it;
// b3 = b2 - gap(t3) with d gap / d t3 = gap (1 - gap / kMaxGap).
std::array<double, 3> chain_to_theta(const FieldCoefficients& c, const std::array<double, 3>& dv) {
  const double gap = c.b2 - c.b3;
  return {dv[0] * c.b1, (dv[1] + dv[2]) * c.b2, -dv[2] * gap * (1.0 - gap / kMaxGap)};
}

// A residual the optimiser can always compare: non-finite values become a large finite one.
double finite_or_large(double v) { return std::isfinite(v) ? v : 1e100; }

// Distance from s and direction from the pan direction of a sample, as AirFieldModel computes
// them: eqs. (1)-(2) for s, then the point rotated into the jet frame.
JetPoint to_jet_frame(const NozzleGeometry& g, const FieldSample& s) {
  const Eigen::Vector2d d = s.p_W - stagnation_point(g, s.orientation);
  const double c = std::cos(s.orientation.pan_rad), sn = std::sin(s.orientation.pan_rad);
  const double along = c * d.x() + sn * d.y();
  const double across = c * d.y() - sn * d.x();
  double u = rad_to_deg(std::atan2(across, along));  // (-180, 180]
  if (u < 0.0) u += kBins;
  int k = static_cast<int>(u);
  if (k >= kBins) k = kBins - 1;  // u just below 360 rounded up
  JetPoint p;
  p.r = d.norm();
  p.bin = k;
  p.frac = u - k;
  p.speed = s.speed_mps;
  return p;
}

// ---- The alpha-independent starting profile -------------------------------------------------

// Residuals sqrt(w_i) (v(r_i) - v_i) of one profile (parameters theta) for all samples of a tilt.
struct ProfileFunctor : Eigen::DenseFunctor<double> {
  explicit ProfileFunctor(const std::vector<JetPoint>& points)
      : Eigen::DenseFunctor<double>(3, static_cast<int>(points.size())), pts(points) {}

  int operator()(const Eigen::VectorXd& t, Eigen::VectorXd& f) const {
    const FieldCoefficients c = from_theta(t.data());
    for (size_t i = 0; i < pts.size(); ++i) {
      f[i] =
          finite_or_large(std::sqrt(pts[i].weight) * (eval_profile(c, pts[i].r).v - pts[i].speed));
    }
    return 0;
  }
  int df(const Eigen::VectorXd& t, Eigen::MatrixXd& jac) const {
    const FieldCoefficients c = from_theta(t.data());
    for (size_t i = 0; i < pts.size(); ++i) {
      const std::array<double, 3> d = chain_to_theta(c, eval_profile(c, pts[i].r).dv);
      for (int j = 0; j < 3; ++j) jac(i, j) = finite_or_large(std::sqrt(pts[i].weight) * d[j]);
    }
    return 0;
  }

  const std::vector<JetPoint>& pts;
};

FieldCoefficients start_profile(const std::vector<JetPoint>& pts) {
  // Grid search over decay rates, b2 = -k2 and b3 = q b2 (q > 1), on at most ~2000 samples;
  // for fixed (b2, b3) the best b1 is a weighted linear least-squares solution.
  const size_t stride = std::max<size_t>(1, pts.size() / 2000);
  double best_cost = INFINITY;
  FieldCoefficients best{1.0, -1.0, -10.0};
  constexpr int kSteps = 30;
  for (int a = 0; a < kSteps; ++a) {
    const double b2 = -std::pow(10.0, -2.0 + 3.3 * a / (kSteps - 1));  // -0.01 .. -20 1/m
    for (int c = 0; c < kSteps; ++c) {
      const double b3 = b2 * std::pow(10.0, 0.1 + 2.9 * c / (kSteps - 1));  // q = 1.26 .. 1000
      double sww = 0.0, swv = 0.0, svv = 0.0;
      for (size_t i = 0; i < pts.size(); i += stride) {
        const double phi = std::exp(b2 * pts[i].r) - std::exp(b3 * pts[i].r);
        sww += pts[i].weight * phi * phi;
        swv += pts[i].weight * phi * pts[i].speed;
        svv += pts[i].weight * pts[i].speed * pts[i].speed;
      }
      if (!(sww > 0.0 && swv > 0.0)) continue;
      const double b1 = swv / sww;
      const double cost = svv - b1 * swv;
      if (cost < best_cost) {
        best_cost = cost;
        best = {b1, b2, b3};
      }
    }
  }
  // Refine on all samples, in theta.
  const std::array<double, 3> t0 = to_theta(best);
  Eigen::VectorXd t = Eigen::Map<const Eigen::Vector3d>(t0.data());
  ProfileFunctor functor(pts);
  Eigen::LevenbergMarquardt<ProfileFunctor> lm(functor);
  lm.setMaxfev(200);
  lm.minimize(t);
  const FieldCoefficients refined = from_theta(t.data());
  if (!(t.allFinite() && std::isfinite(refined.b1) && refined.b1 > 0 && refined.b3 < refined.b2)) {
    return best;
  }
  return refined;
}

// ---- The joint fit of the 360 x 3 parameters of one tilt -------------------------------------

// The residuals of one tilt's joint fit, in this row order:
//   [0, 1080)      smoothness, row 3 k + j:  c D2 theta_j[k]
//   [1080, 2160)   anchor,     row 3 k + j:  a (theta_j[k] - theta_j of the start profile)
//   [2160, ...)    samples, sorted by bin:   sqrt(w_i) (v_model - v_i)
// Parameters x[3 k + j] = theta_j of bin k, in bin order, kept in that order (natural ordering).
// Eigen's SparseQR is left-looking and takes row c as the pivot row of column c; the smoothness
// rows hold the diagonal, so the factor R stays banded (plus the wrap-around at 360 deg). COLAMD,
// or the samples first, make the factorisation an order of magnitude slower.
struct RingProblem {
  std::vector<JetPoint> pts;
  double smooth_scale = 0.0;  // c
  double anchor_scale = 0.0;  // a
  std::array<double, 3> start{};
};

// SparseQR that keeps every pivot, however small. Eigen's sparse LM step (lmqrsolv) reads the
// diagonal of R unconditionally and overruns its storage when a pivot was dropped as
// rank-deficient; the anchor rows make the problem full rank, so no pivot is truly zero.
template <typename Matrix>
class AllPivotsSparseQR : public Eigen::SparseQR<Matrix, Eigen::NaturalOrdering<int>> {
 public:
  explicit AllPivotsSparseQR(const Matrix& m) {
    this->setPivotThreshold(std::numeric_limits<double>::min());
    this->compute(m);
  }
};

class RingFunctor : public Eigen::SparseFunctor<double, int> {
 public:
  using QRSolver = AllPivotsSparseQR<JacobianType>;

  explicit RingFunctor(const RingProblem& p)
      : Eigen::SparseFunctor<double, int>(kParams, 2 * kParams + static_cast<int>(p.pts.size())),
        p_(p) {}

  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& f) const {
    for (int k = 0; k < kBins; ++k) {
      const int prev = 3 * ((k + kBins - 1) % kBins), here = 3 * k, next = 3 * ((k + 1) % kBins);
      for (int j = 0; j < 3; ++j) {
        f[here + j] = p_.smooth_scale * (x[prev + j] - 2.0 * x[here + j] + x[next + j]);
        f[kParams + here + j] = p_.anchor_scale * (x[here + j] - p_.start[j]);
      }
    }
    const Ring ring = profiles(x);
    for (size_t i = 0; i < p_.pts.size(); ++i) {
      const JetPoint& p = p_.pts[i];
      const double v = eval_profile(interpolate(ring, p), p.r).v;
      f[2 * kParams + i] = finite_or_large(std::sqrt(p.weight) * (v - p.speed));
    }
    return 0;
  }

  int df(const Eigen::VectorXd& x, JacobianType& jac) const {
    std::vector<Eigen::Triplet<double, int>> t;
    t.reserve(10 * kParams + 6 * p_.pts.size());
    for (int k = 0; k < kBins; ++k) {
      const int prev = 3 * ((k + kBins - 1) % kBins), here = 3 * k, next = 3 * ((k + 1) % kBins);
      for (int j = 0; j < 3; ++j) {
        t.emplace_back(here + j, prev + j, p_.smooth_scale);
        t.emplace_back(here + j, here + j, -2.0 * p_.smooth_scale);
        t.emplace_back(here + j, next + j, p_.smooth_scale);
        t.emplace_back(kParams + here + j, here + j, p_.anchor_scale);
      }
    }
    const Ring ring = profiles(x);
    for (size_t i = 0; i < p_.pts.size(); ++i) {
      const JetPoint& p = p_.pts[i];
      const int row = 2 * kParams + static_cast<int>(i);
      const int k1 = (p.bin + 1) % kBins;
      const double sw = std::sqrt(p.weight);
      const std::array<double, 3> dv = eval_profile(interpolate(ring, p), p.r).dv;
      // The sample sees bin k with weight 1 - frac and bin k + 1 with weight frac.
      const std::array<double, 3> d0 = chain_to_theta(ring[p.bin], dv);
      const std::array<double, 3> d1 = chain_to_theta(ring[k1], dv);
      for (int j = 0; j < 3; ++j) {
        t.emplace_back(row, 3 * p.bin + j, finite_or_large(sw * (1.0 - p.frac) * d0[j]));
        t.emplace_back(row, 3 * k1 + j, finite_or_large(sw * p.frac * d1[j]));
      }
    }
    jac.resize(values(), inputs());
    jac.setFromTriplets(t.begin(), t.end());
    jac.makeCompressed();
    return 0;
  }

  // The eq. (3) coefficients of every bin.
  static Ring profiles(const Eigen::VectorXd& x) {
    Ring ring;
    for (int k = 0; k < kBins; ++k) ring[k] = from_theta(x.data() + 3 * k);
    return ring;
  }

 private:
  // The model's linear interpolation between the two neighbouring bins.
  static FieldCoefficients interpolate(const Ring& ring, const JetPoint& p) {
    const FieldCoefficients& a = ring[p.bin];
    const FieldCoefficients& b = ring[(p.bin + 1) % kBins];
    const double w = p.frac;
    return {a.b1 + w * (b.b1 - a.b1), a.b2 + w * (b.b2 - a.b2), a.b3 + w * (b.b3 - a.b3)};
  }

  const RingProblem& p_;
};

const char* status_text(Eigen::LevenbergMarquardtSpace::Status s) {
  using namespace Eigen::LevenbergMarquardtSpace;
  switch (s) {
    case RelativeReductionTooSmall:
      return "converged: relative reduction of the cost below ftol";
    case RelativeErrorTooSmall:
      return "converged: relative change of the coefficients below xtol";
    case RelativeErrorAndReductionTooSmall:
      return "converged: cost and coefficients settled";
    case CosinusTooSmall:
      return "converged: gradient orthogonal to the residuals";
    case TooManyFunctionEvaluation:
      return "stopped: evaluation budget exhausted";
    case FtolTooSmall:
      return "converged: cost at machine precision";
    case XtolTooSmall:
      return "converged: coefficients at machine precision";
    case GtolTooSmall:
      return "converged: gradient at machine precision";
    case ImproperInputParameters:
      return "failed: improper input parameters or QR failure";
    case UserAsked:
      return "stopped by the residual function";
    default:
      return "unknown";
  }
}

// The fit of one tilt: coefficients for every 1-degree bin and what the report needs of it.
struct TiltFit {
  Ring ring;
  TiltFitReport report;
};

TiltFit fit_tilt(const TiltSamples& samples, const FieldFitOptions& o) {
  TiltFit out;
  // Samples in the jet frame, weighted: fusion share over the source's count.
  std::vector<JetPoint> pts;
  pts.reserve(samples.grid.size() + samples.cfd.size());
  const bool fuse = !samples.grid.empty() && !samples.cfd.empty();
  for (const FieldSample* s : samples.grid) {
    JetPoint p = to_jet_frame(o.geometry, *s);
    const double share = fuse ? 1.0 - cfd_fusion_share(p.r, o.fusion_length_m) : 1.0;
    p.weight = share / static_cast<double>(samples.grid.size());
    pts.push_back(p);
  }
  for (const FieldSample* s : samples.cfd) {
    JetPoint p = to_jet_frame(o.geometry, *s);
    const double share = fuse ? cfd_fusion_share(p.r, o.fusion_length_m) : 1.0;
    p.weight = share / static_cast<double>(samples.cfd.size());
    pts.push_back(p);
  }
  // Sorted by direction: the rows of the Jacobian then form a band (see RingFunctor).
  std::stable_sort(pts.begin(), pts.end(),
                   [](const JetPoint& a, const JetPoint& b) { return a.bin < b.bin; });
  std::array<bool, kBins> covered{};
  for (const JetPoint& p : pts) covered[p.bin] = true;
  out.report.alpha_bins_with_data =
      static_cast<int>(std::count(covered.begin(), covered.end(), true));

  // Start: one profile for all directions.
  const FieldCoefficients start = start_profile(pts);
  out.report.start_profile = start;

  // Penalty and anchor scales: a relative ripple of a coefficient costs like the same relative
  // ripple of the speed (the RMS data speed), balanced per bin against the data weight.
  double total_weight = 0.0, speed2 = 0.0;
  for (const JetPoint& p : pts) {
    total_weight += p.weight;
    speed2 += p.weight * p.speed * p.speed;
  }
  const double per_bin = std::sqrt(total_weight / kBins) * std::sqrt(speed2 / total_weight);
  RingProblem problem;
  problem.start = to_theta(start);
  problem.smooth_scale = std::pow(o.smoothing_deg / (2.0 * kPi), 2) * per_bin;
  problem.anchor_scale = kAnchorRatio * per_bin;
  problem.pts = std::move(pts);

  // Joint nonlinear least squares over all bins.
  Eigen::VectorXd x(kParams);
  for (int k = 0; k < kBins; ++k) {
    x.segment<3>(3 * k) = Eigen::Map<const Eigen::Vector3d>(problem.start.data());
  }
  RingFunctor functor(problem);
  Eigen::LevenbergMarquardt<RingFunctor> lm(functor);
  lm.setMaxfev(o.max_evaluations);
  // Step by step, so that a fit that runs out of its time budget keeps the best answer so far
  // (LevenbergMarquardt accepts only steps that lower the cost).
  using Status = Eigen::LevenbergMarquardtSpace::Status;
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(o.time_budget_s);
  Status status = lm.minimizeInit(x);
  if (status != Eigen::LevenbergMarquardtSpace::ImproperInputParameters) {
    do {
      status = lm.minimizeOneStep(x);
    } while (status == Eigen::LevenbergMarquardtSpace::Running &&
             std::chrono::steady_clock::now() < deadline);
  }
  const bool out_of_time = status == Eigen::LevenbergMarquardtSpace::Running;
  out.report.lm_iterations = static_cast<int>(lm.njev());
  out.report.lm_evaluations = static_cast<int>(lm.nfev());
  out.report.lm_status = out_of_time ? "stopped: time budget exhausted" : status_text(status);
  out.report.lm_converged = !out_of_time && lm.info() == Eigen::Success &&
                            status != Eigen::LevenbergMarquardtSpace::TooManyFunctionEvaluation;
  // A profile far outside any physical range means the data are not eq. (3)-shaped.
  out.ring = RingFunctor::profiles(x);
  for (const FieldCoefficients& c : out.ring) {
    if (!(std::abs(c.b1) <= kMaxCoefficient && std::abs(c.b2) <= kMaxCoefficient &&
          std::abs(c.b3) <= kMaxCoefficient)) {
      throw InputError(samples.sources + ": the fit at tilt " + tilt_text(samples.tilt_rad) +
                       " deg diverged (a coefficient beyond 1e9); the samples cannot be "
                       "described by eq. (3)");
    }
  }
  return out;
}

// Quantised tilt (1e-6 deg), the grouping key of samples into tilts.
std::int64_t tilt_key(double tilt_rad) { return std::llround(rad_to_deg(tilt_rad) * 1e6); }

// Agreement of the fitted model (evaluated by AirFieldModel itself) with one source.
void add_stats(const AirFieldModel& model, const std::vector<const FieldSample*>& samples,
               const FieldFitOptions& o, SourceFitStats* stats, TiltFitReport* report,
               bool directions) {
  std::map<std::pair<double, double>, OrientedField> fields;
  double ape_sum = 0.0, se_sum = 0.0, angle_sum = 0.0;
  size_t n_ape = 0, n_angle = 0;
  for (const FieldSample* s : samples) {
    const auto key = std::make_pair(s->orientation.pan_rad, s->orientation.tilt_rad);
    auto it = fields.find(key);
    if (it == fields.end()) it = fields.emplace(key, model.at(s->orientation)).first;
    const OrientedField& f = it->second;
    const double v = f.speed(s->p_W);
    se_sum += (v - s->speed_mps) * (v - s->speed_mps);
    if (s->speed_mps >= o.mape_min_speed_mps && s->speed_mps > 0.0) {
      ape_sum += std::abs(v - s->speed_mps) / s->speed_mps;
      ++n_ape;
    }
    // Direction: the model's is radial from s (section III-A).
    const Eigen::Vector2d radial = s->p_W - f.stagnation_point();
    if (directions && s->v_W.norm() >= o.mape_min_speed_mps && radial.norm() > 1e-9) {
      const double cross = radial.x() * s->v_W.y() - radial.y() * s->v_W.x();
      angle_sum += std::atan2(std::abs(cross), radial.dot(s->v_W));
      ++n_angle;
    }
  }
  stats->n_samples = samples.size();
  stats->n_mape_samples = n_ape;
  if (!samples.empty()) stats->rmse_mps = std::sqrt(se_sum / static_cast<double>(samples.size()));
  if (n_ape > 0) stats->mape_pct = 100.0 * ape_sum / static_cast<double>(n_ape);
  if (directions) {
    report->n_direction_samples = n_angle;
    if (n_angle > 0) report->cfd_direction_error_deg = rad_to_deg(angle_sum / n_angle);
  }
}

}  // namespace

void FieldFitOptions::validate() const {
  geometry.validate();
  auto bad = [](const std::string& what) { throw InputError("field fit options: " + what); };
  if (!(std::isfinite(fusion_length_m) && fusion_length_m > 0 && fusion_length_m <= 100)) {
    bad("fusion_length_m must be in (0, 100] m, got " + std::to_string(fusion_length_m));
  }
  if (!(std::isfinite(smoothing_deg) && smoothing_deg >= 1 && smoothing_deg <= 180)) {
    bad("smoothing_deg must be in [1, 180] deg, got " + std::to_string(smoothing_deg));
  }
  if (!(std::isfinite(mape_min_speed_mps) && mape_min_speed_mps >= 0)) {
    bad("mape_min_speed_mps must be >= 0, got " + std::to_string(mape_min_speed_mps));
  }
  if (max_evaluations < 1) bad("max_evaluations must be >= 1");
  if (!(time_budget_s > 0)) bad("time_budget_s must be > 0");
  if (threads < 0) bad("threads must be >= 0");
}

double cfd_fusion_share(double r_m, double fusion_length_m) {
  const double l2 = fusion_length_m * fusion_length_m;
  return l2 / (l2 + r_m * r_m);
}

FieldFitResult fit_field_table(const FieldGrid& grid, const FieldGrid* cfd,
                               const FieldFitOptions& options) {
  options.validate();
  if (grid.kind != GridKind::kMeasured) {
    throw InputError(grid.source + ": expected a measured grid (pan_deg,tilt_deg,x,y,speed)");
  }
  if (cfd != nullptr && cfd->kind != GridKind::kSimulated) {
    throw InputError(cfd->source + ": expected a CFD grid with velocity columns vx, vy");
  }
  validate_field_grid(grid);
  if (cfd != nullptr) validate_field_grid(*cfd);

  // Group the samples by tilt (both sources together), in increasing tilt.
  std::map<std::int64_t, TiltSamples> by_tilt;
  std::map<std::int64_t, double> tilt_rad;
  for (const FieldSample& s : grid.samples) {
    by_tilt[tilt_key(s.orientation.tilt_rad)].grid.push_back(&s);
    tilt_rad.emplace(tilt_key(s.orientation.tilt_rad), s.orientation.tilt_rad);
  }
  if (cfd != nullptr) {
    for (const FieldSample& s : cfd->samples) {
      by_tilt[tilt_key(s.orientation.tilt_rad)].cfd.push_back(&s);
      tilt_rad.emplace(tilt_key(s.orientation.tilt_rad), s.orientation.tilt_rad);
    }
  }
  const std::string sources = grid.source + (cfd != nullptr ? " and " + cfd->source : "");
  if (static_cast<int>(by_tilt.size()) < FieldTable::kMinTilts) {
    std::string found;
    for (const auto& [key, rad] : tilt_rad) found += (found.empty() ? "" : ", ") + tilt_text(rad);
    throw InputError(sources + ": " + std::to_string(by_tilt.size()) + " distinct tilt(s) (" +
                     found + " deg), at least " + std::to_string(FieldTable::kMinTilts) +
                     " are needed for Makima interpolation in tilt");
  }
  double previous_tilt = -INFINITY;
  for (auto& [key, t] : by_tilt) {
    t.tilt_rad = tilt_rad[key];
    t.sources = t.cfd.empty() ? grid.source : t.grid.empty() ? cfd->source : sources;
    // Distinct tilts closer than kMinTiltSpacing are a typo, not a Makima node.
    if (rad_to_deg(t.tilt_rad - previous_tilt) < kMinTiltSpacingDeg) {
      throw InputError(sources + ": tilts " + tilt_text(previous_tilt) + " and " +
                       tilt_text(t.tilt_rad) + " deg are distinct but closer than " +
                       tilt_text(deg_to_rad(kMinTiltSpacingDeg)) + " deg; use one value per tilt");
    }
    previous_tilt = t.tilt_rad;
    auto check = [&t = t](const std::vector<const FieldSample*>& v, const std::string& source) {
      if (!v.empty() && v.size() < kMinSamplesPerTilt) {
        throw InputError(source + ": tilt " + tilt_text(t.tilt_rad) + " deg has " +
                         std::to_string(v.size()) + " sample(s), at least " +
                         std::to_string(kMinSamplesPerTilt) + " are needed (e.g. a 4 x 4 grid)");
      }
    };
    check(t.grid, grid.source);
    if (cfd != nullptr) check(t.cfd, cfd->source);
    // eq. (3) needs some air: all-zero speeds leave b1 = 0 and nothing else determined.
    double max_speed = 0.0;
    for (const auto* v : {&t.grid, &t.cfd}) {
      for (const FieldSample* s : *v) max_speed = std::max(max_speed, s->speed_mps);
    }
    if (!(max_speed > 0.0)) {
      throw InputError(t.sources + ": every speed at tilt " + tilt_text(t.tilt_rad) +
                       " deg is zero; there is no jet to fit");
    }
  }

  // Fit the tilts, several at a time; each fit is independent and deterministic.
  std::vector<const TiltSamples*> jobs;
  for (const auto& [key, t] : by_tilt) jobs.push_back(&t);
  const int hw = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const size_t parallel = static_cast<size_t>(options.threads > 0 ? options.threads : hw);
  std::vector<TiltFit> fits(jobs.size());
  for (size_t start = 0; start < jobs.size(); start += parallel) {
    const size_t end = std::min(jobs.size(), start + parallel);
    std::vector<std::future<TiltFit>> running;
    for (size_t i = start + 1; i < end; ++i) {
      running.push_back(
          std::async(std::launch::async, fit_tilt, std::cref(*jobs[i]), std::cref(options)));
    }
    fits[start] = fit_tilt(*jobs[start], options);
    for (size_t i = start + 1; i < end; ++i) fits[i] = running[i - start - 1].get();
  }

  // The table, then the model's agreement with each source.
  std::vector<double> tilts;
  std::vector<Ring> rings;
  for (const auto& [key, rad] : tilt_rad) tilts.push_back(rad);
  for (const TiltFit& f : fits) rings.push_back(f.ring);
  FieldFitResult result{FieldTable(tilts, std::move(rings)), {}};
  const AirFieldModel model(options.geometry, result.table);
  for (size_t i = 0; i < jobs.size(); ++i) {
    TiltFitReport r = fits[i].report;
    r.tilt_rad = tilts[i];
    add_stats(model, jobs[i]->grid, options, &r.grid, &r, false);
    add_stats(model, jobs[i]->cfd, options, &r.cfd, &r, true);
    result.tilts.push_back(std::move(r));
  }
  return result;
}

std::vector<TiltFitReport> evaluate_field_table(const FieldTable& table, const FieldGrid* grid,
                                                const FieldGrid* cfd,
                                                const FieldFitOptions& options) {
  options.validate();
  if (grid == nullptr && cfd == nullptr) throw InputError("table evaluation: no samples given");
  if (grid != nullptr && grid->kind != GridKind::kMeasured) {
    throw InputError(grid->source + ": expected a measured grid (pan_deg,tilt_deg,x,y,speed)");
  }
  if (cfd != nullptr && cfd->kind != GridKind::kSimulated) {
    throw InputError(cfd->source + ": expected a CFD grid with velocity columns vx, vy");
  }
  // Group the samples of each source by tilt.
  std::map<std::int64_t, TiltSamples> by_tilt;
  std::map<std::int64_t, double> tilt_rad;
  if (grid != nullptr) {
    validate_field_grid(*grid);
    for (const FieldSample& s : grid->samples) {
      by_tilt[tilt_key(s.orientation.tilt_rad)].grid.push_back(&s);
      tilt_rad.emplace(tilt_key(s.orientation.tilt_rad), s.orientation.tilt_rad);
    }
  }
  if (cfd != nullptr) {
    validate_field_grid(*cfd);
    for (const FieldSample& s : cfd->samples) {
      by_tilt[tilt_key(s.orientation.tilt_rad)].cfd.push_back(&s);
      tilt_rad.emplace(tilt_key(s.orientation.tilt_rad), s.orientation.tilt_rad);
    }
  }
  // The table's agreement with each source, tilt by tilt.
  const AirFieldModel model(options.geometry, table);
  std::vector<TiltFitReport> reports;
  for (const auto& [key, t] : by_tilt) {
    TiltFitReport r;
    r.tilt_rad = tilt_rad[key];
    r.lm_status = "not fitted";
    add_stats(model, t.grid, options, &r.grid, &r, false);
    add_stats(model, t.cfd, options, &r.cfd, &r, true);
    reports.push_back(std::move(r));
  }
  return reports;
}

}  // namespace airtwin
