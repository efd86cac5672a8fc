#include "models/discrepancy_correction.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <span>
#include <string>
#include <thread>

#include "common/parallel_for.h"
#include "common/units.h"
#include "models/discrepancy_evaluation.h"
#include "models/discrepancy_report.h"
#include "models/discrepancy_statistics.h"

namespace airtwin::discrepancy_detail {
namespace {

constexpr int kHalfSpan = 2;        // samples each side of the local quadratic
constexpr double kMinSpeed = 0.05;  // m/s: a sample informs when the measurement or the model
                                    // moves at least this fast (both at rest: no information)
constexpr int kFolds = 5;
constexpr int kSignFlips = 4999;  // resamples of the held-out test (p resolves 2e-4)
// Where the data are thin the smoother shrinks toward no correction: as if this many samples of
// zero residual sat at every point.
constexpr double kPriorSamples = 2.0;
// The loss of a residual r is min(|r|^2, c^2), c this many times the median |r| before any
// correction: a few samples where the local quadratic straddles a collision or a jerk of the
// turbulence do not decide.
constexpr double kClip = 3.0;
// A correction whose RMS over the held-out samples is below this (m/s^2) is negligible whatever
// its significance: 1 % of a tracer's kinetic friction (eq. (8)'s 8.53 m/s^2), and five times what
// the estimator leaves on trajectories the model itself made (its state at the span's first
// sample is the quadratic's, not the true one).
constexpr double kNegligibleCorrection = 0.1;
// Support that `where` reports from: at least this many samples' weight.
constexpr double kWhereSupport = 10.0;

struct Sample {
  size_t window = 0;
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();  // floor position (m)
  Eigen::Vector2d p_S = Eigen::Vector2d::Zero();  // from s, x downstream (m)
  double since_change_s = 0.0;
  // Residual acceleration (m/s^2), measured minus model, along the radial direction from s and
  // across it (counter-clockwise).
  double radial = 0.0, across = 0.0;
};

// A feature group: its grid and the bandwidths tried.
struct Group {
  const char* name;
  const char* unit;
  double x0, y0, step;
  int nx, ny;
  std::array<double, 4> bandwidths;
  std::function<Eigen::Vector2d(const Sample&)> feature;
};

std::vector<Group> groups() {
  return {
      {"position_from_s",
       "m",
       -1.2,
       -1.2,
       0.025,
       97,
       97,
       {0.05, 0.1, 0.2, 0.4},
       [](const Sample& s) { return s.p_S; }},
      {"floor_position",
       "m",
       -1.5,
       -1.5,
       0.025,
       121,
       121,
       {0.05, 0.1, 0.2, 0.4},
       [](const Sample& s) { return s.p_W; }},
      {"time_since_command",
       "s",
       0.0,
       0.0,
       0.02,
       151,
       1,
       {0.05, 0.1, 0.2, 0.4},
       [](const Sample& s) { return Eigen::Vector2d(s.since_change_s, 0.0); }},
  };
}

// The informative samples of every window with their residual accelerations under `ext`.
std::vector<Sample> acceleration_samples(const ExtendedPredictor& pred, const WindowSet& ws,
                                         const ModelExtensions& ext) {
  std::vector<Sample> out;
  std::vector<Eigen::Vector2d> model_p;
  std::vector<size_t> all(ws.windows.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  const std::map<std::string, ModelExtensions> typed = extensions_by_type(ext, ws, all);
  for (size_t wi = 0; wi < ws.windows.size(); ++wi) {
    const Window& w = ws.windows[wi];
    const size_t n = w.times.size();
    for (size_t k = kHalfSpan; k + kHalfSpan < n; ++k) {
      // p(t_k + tau) = c0 + c1 tau + c2 tau^2 by least squares over the span, for the
      // measurement and for the model started from the measurement's state at the span's first
      // sample: the same estimator on both, so that its own bias (the motion is not quadratic
      // over the span) cancels in the difference.
      const size_t first = k - kHalfSpan;
      Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
      for (size_t j = first; j <= k + kHalfSpan; ++j) {
        const double tau = w.times[j] - w.times[k];
        const Eigen::Vector3d row(1.0, tau, tau * tau);
        ata += row * row.transpose();
      }
      const Eigen::LDLT<Eigen::Matrix3d> ldlt(ata);
      auto quadratic = [&](auto position) {
        Eigen::Matrix<double, 3, 2> atb = Eigen::Matrix<double, 3, 2>::Zero();
        for (size_t j = first; j <= k + kHalfSpan; ++j) {
          const double tau = w.times[j] - w.times[k];
          atb += Eigen::Vector3d(1.0, tau, tau * tau) * position(j).transpose();
        }
        return Eigen::Matrix<double, 3, 2>(ldlt.solve(atb));
      };
      const Eigen::Matrix<double, 3, 2> c =
          quadratic([&](size_t j) -> Eigen::Vector2d { return w.measured[j]; });
      if (!c.allFinite()) continue;
      const double tau0 = w.times[first] - w.times[k];
      WindowStart from;
      from.t_s = w.times[first];
      from.p_W = (c.row(0) + tau0 * c.row(1) + tau0 * tau0 * c.row(2)).transpose();
      from.v_W = (c.row(1) + 2.0 * tau0 * c.row(2)).transpose();
      // An object the measurement shows at rest starts at rest (the quadratic's slope there is
      // noise).
      if (from.v_W.norm() < kMinSpeed) from.v_W.setZero();
      pred.predict(*w.xi, typed.empty() ? ext : typed.at(*w.type), *w.timeline, from,
                   std::span<const double>(w.times.data() + first, 2 * kHalfSpan + 1), &model_p);
      const Eigen::Matrix<double, 3, 2> m =
          quadratic([&](size_t j) -> Eigen::Vector2d { return model_p[j - first]; });
      if (c.row(1).norm() < kMinSpeed && m.row(1).norm() < kMinSpeed) continue;
      const OrientedRays rays =
          pred.field().rays_at(pred.field_orientation(ext, *w.timeline, w.times[k]));
      const double pan = rays.orientation().pan_rad;
      Sample s;
      s.window = wi;
      s.p_W = c.row(0).transpose();
      const Eigen::Vector2d d = s.p_W - rays.stagnation_point();
      s.p_S = Eigen::Vector2d(std::cos(pan) * d.x() + std::sin(pan) * d.y(),
                              -std::sin(pan) * d.x() + std::cos(pan) * d.y());
      s.since_change_s = w.since_change_s[k];
      const Eigen::Vector2d e = 2.0 * (c.row(2) - m.row(2)).transpose();
      const double r = d.norm();
      const Eigen::Vector2d radial = r > 0.0 ? Eigen::Vector2d(d / r) : Eigen::Vector2d(1.0, 0.0);
      s.radial = e.dot(radial);
      s.across = e.dot(Eigen::Vector2d(-radial.y(), radial.x()));
      out.push_back(s);
    }
  }
  return out;
}

// A kernel smoother of the residual over one group's grid.
class Smoother {
 public:
  Smoother(const Group& g, double bandwidth) : g_(g), bandwidth_(bandwidth) {
    const double sigma = bandwidth / g.step;
    const int radius = static_cast<int>(std::ceil(3.0 * sigma));
    double sum = 0.0;
    for (int i = -radius; i <= radius; ++i) {
      kernel_.push_back(std::exp(-0.5 * i * i / (sigma * sigma)));
      sum += kernel_.back();
    }
    for (double& k : kernel_) k /= sum;
    const double centre = kernel_[static_cast<size_t>(radius)];
    prior_ = kPriorSamples * (g.ny > 1 ? centre * centre : centre);
  }

  // Fits the grid to the samples for which `use` holds.
  void fit(const std::vector<Sample>& samples, const std::function<bool(const Sample&)>& use) {
    const size_t cells = static_cast<size_t>(g_.nx) * static_cast<size_t>(g_.ny);
    std::vector<double> sa(cells, 0.0), sc(cells, 0.0), sw(cells, 0.0);
    for (const Sample& s : samples) {
      if (!use(s)) continue;
      const long c = cell(g_.feature(s));
      if (c < 0) continue;
      sa[static_cast<size_t>(c)] += s.radial;
      sc[static_cast<size_t>(c)] += s.across;
      sw[static_cast<size_t>(c)] += 1.0;
    }
    blur(&sa);
    blur(&sc);
    blur(&sw);
    radial_.assign(cells, 0.0);
    across_.assign(cells, 0.0);
    for (size_t i = 0; i < cells; ++i) {
      radial_[i] = sa[i] / (sw[i] + prior_);
      across_[i] = sc[i] / (sw[i] + prior_);
    }
    weight_ = std::move(sw);
  }

  // The correction at a sample's features (zero off the grid).
  Eigen::Vector2d at(const Sample& s) const {
    const long c = cell(g_.feature(s));
    if (c < 0) return Eigen::Vector2d::Zero();
    return Eigen::Vector2d(radial_[static_cast<size_t>(c)], across_[static_cast<size_t>(c)]);
  }

  void store(ResidualCorrection* out) const {
    out->feature = g_.name;
    out->unit = g_.unit;
    out->bandwidth = bandwidth_;
    out->x0 = g_.x0;
    out->y0 = g_.y0;
    out->step = g_.step;
    out->nx = g_.nx;
    out->ny = g_.ny;
    out->radial = radial_;
    out->across = across_;
    out->weight = weight_;
  }

  // Weight one sample puts on its own cell: the unit of `weight_` in samples.
  double sample_weight() const { return prior_ / kPriorSamples; }

 private:
  long cell(const Eigen::Vector2d& f) const {
    const long i = std::lround((f.x() - g_.x0) / g_.step);
    const long j = g_.ny > 1 ? std::lround((f.y() - g_.y0) / g_.step) : 0;
    if (i < 0 || i >= g_.nx || j < 0 || j >= g_.ny) return -1;
    return j * g_.nx + i;
  }

  // Separable Gaussian blur of a grid (zero outside it).
  void blur(std::vector<double>* grid) const {
    const int radius = static_cast<int>(kernel_.size() / 2);
    std::vector<double> tmp(grid->size(), 0.0);
    for (int j = 0; j < g_.ny; ++j) {
      for (int i = 0; i < g_.nx; ++i) {
        double acc = 0.0;
        for (int q = -radius; q <= radius; ++q) {
          const int ii = i + q;
          if (ii >= 0 && ii < g_.nx) acc += kernel_[q + radius] * (*grid)[j * g_.nx + ii];
        }
        tmp[j * g_.nx + i] = acc;
      }
    }
    if (g_.ny == 1) {
      *grid = std::move(tmp);
      return;
    }
    for (int j = 0; j < g_.ny; ++j) {
      for (int i = 0; i < g_.nx; ++i) {
        double acc = 0.0;
        for (int q = -radius; q <= radius; ++q) {
          const int jj = j + q;
          if (jj >= 0 && jj < g_.ny) acc += kernel_[q + radius] * tmp[jj * g_.nx + i];
        }
        (*grid)[j * g_.nx + i] = acc;
      }
    }
  }

  const Group& g_;
  double bandwidth_;
  std::vector<double> kernel_;
  double prior_ = 0.0;
  std::vector<double> radial_, across_, weight_;
};

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

double loss(double radial, double across, double clip) {
  return std::min(radial * radial + across * across, clip * clip);
}

// Where the correction is largest among cells the data support, in words.
std::string describe_peak(const ResidualCorrection& c, double sample_weight) {
  double best = -1.0;
  int bi = -1, bj = -1;
  for (int j = 0; j < c.ny; ++j) {
    for (int i = 0; i < c.nx; ++i) {
      const size_t k = static_cast<size_t>(j * c.nx + i);
      if (c.weight[k] < kWhereSupport * sample_weight) continue;
      const double m = std::hypot(c.radial[k], c.across[k]);
      if (m > best) {
        best = m;
        bi = i;
        bj = j;
      }
    }
  }
  if (bi < 0) return "nowhere with enough data";
  const size_t k = static_cast<size_t>(bj * c.nx + bi);
  const double x = c.x0 + bi * c.step, y = c.y0 + bj * c.step;
  std::string place;
  if (c.feature == "position_from_s") {
    place = fixed(std::hypot(x, y), 2) + " m from s at alpha " +
            fixed(rad_to_deg(std::atan2(y, x)), 0) + " deg (0: downstream)";
  } else if (c.feature == "floor_position") {
    place = "around (" + fixed(x, 2) + ", " + fixed(y, 2) + ") m on the floor";
  } else {
    place = fixed(x, 2) + " s after the command changed";
  }
  return place + ": " + fixed(std::abs(c.radial[k]), 2) + " m/s^2 " +
         (c.radial[k] < 0.0 ? "inward" : "outward") + " and " + fixed(std::abs(c.across[k]), 2) +
         " m/s^2 " + (c.across[k] < 0.0 ? "clockwise" : "counter-clockwise") +
         " about s, measured minus model";
}

}  // namespace

CorrectionOutcome correct_residual(const ExtendedPredictor& predictor, const WindowSet& ws,
                                   const ModelExtensions& ext, const std::vector<size_t>& train,
                                   const std::vector<size_t>& held, double alpha, double min_gain) {
  CorrectionOutcome out;
  std::vector<Sample> samples = acceleration_samples(predictor, ws, ext);
  out.n_samples = samples.size();
  std::vector<int> fold(ws.windows.size(), -1);  // training windows: their fold; held-out: -1
  for (size_t i = 0; i < train.size(); ++i) fold[train[i]] = static_cast<int>(i % kFolds);
  std::vector<char> is_held(ws.windows.size(), 0);
  for (size_t i : held) is_held[i] = 1;
  // A residual of the same size everywhere is not a structure (a uniformly stronger or weaker
  // push is the catalogue's; and a gust that speeds an object up keeps pushing it, so the
  // turbulence alone leaves a small outward residual on moving objects): the training median of
  // each component is taken out first, and the smoothers are judged against that constant.
  std::vector<double> radial, across;
  for (const Sample& s : samples) {
    if (fold[s.window] < 0) continue;
    radial.push_back(s.radial);
    across.push_back(s.across);
  }
  if (radial.size() < 10 * kFolds) return out;
  out.median_residual = Eigen::Vector2d(median(radial), median(across));
  for (Sample& s : samples) {
    s.radial -= out.median_residual.x();
    s.across -= out.median_residual.y();
  }
  std::vector<double> train_norms;
  for (const Sample& s : samples) {
    if (fold[s.window] >= 0) train_norms.push_back(std::hypot(s.radial, s.across));
  }
  std::nth_element(train_norms.begin(), train_norms.begin() + train_norms.size() / 2,
                   train_norms.end());
  const double clip = kClip * train_norms[train_norms.size() / 2];

  // Every group's cross-validated gain at every bandwidth, the (group, bandwidth) pairs in
  // parallel: each its own smoothers, the sums in a fixed order (the same bytes on any threads).
  const std::vector<Group> gs = groups();
  const size_t n_bw = gs.front().bandwidths.size();
  std::vector<double> cv(gs.size() * n_bw, 0.0);
  const unsigned hw = std::thread::hardware_concurrency();
  parallel_for(cv.size(), static_cast<int>(std::clamp<unsigned>(hw, 1, 8)), [&](size_t item) {
    const Group& g = gs[item / n_bw];
    const double bw = g.bandwidths[item % n_bw];
    double before = 0.0, after = 0.0;
    for (int f = 0; f < kFolds; ++f) {
      Smoother sm(g, bw);
      sm.fit(samples, [&](const Sample& s) { return fold[s.window] >= 0 && fold[s.window] != f; });
      for (const Sample& s : samples) {
        if (fold[s.window] != f) continue;
        const Eigen::Vector2d c = sm.at(s);
        before += loss(s.radial, s.across, clip);
        after += loss(s.radial - c.x(), s.across - c.y(), clip);
      }
    }
    cv[item] = before > 0.0 ? 1.0 - after / before : 0.0;
  });
  double best_cv = 0.0;
  for (size_t gi = 0; gi < gs.size(); ++gi) {
    const Group& g = gs[gi];
    // The bandwidth with the best cross-validated gain (the first of equals).
    double cv_gain = -INFINITY, bandwidth = g.bandwidths[0];
    for (size_t b = 0; b < n_bw; ++b) {
      if (cv[gi * n_bw + b] > cv_gain) {
        cv_gain = cv[gi * n_bw + b];
        bandwidth = g.bandwidths[b];
      }
    }
    // Fitted on every training window, scored once on the held-out ones.
    Smoother sm(g, bandwidth);
    sm.fit(samples, [&](const Sample& s) { return fold[s.window] >= 0; });
    std::vector<double> before_w(ws.windows.size(), 0.0), after_w(ws.windows.size(), 0.0);
    std::vector<int> count_w(ws.windows.size(), 0);
    double before = 0.0, after = 0.0, size = 0.0;
    int n_held = 0;
    for (const Sample& s : samples) {
      if (!is_held[s.window]) continue;
      const Eigen::Vector2d c = sm.at(s);
      size += c.squaredNorm();
      ++n_held;
      const double b = loss(s.radial, s.across, clip),
                   a = loss(s.radial - c.x(), s.across - c.y(), clip);
      before_w[s.window] += b;
      after_w[s.window] += a;
      ++count_w[s.window];
      before += b;
      after += a;
    }
    std::vector<double> diffs;
    for (size_t i : held) {
      if (count_w[i] > 0) diffs.push_back((before_w[i] - after_w[i]) / count_w[i]);
    }
    ResidualCorrection rc;
    sm.store(&rc);
    rc.cv_gain = cv_gain;
    rc.heldout_gain = before > 0.0 ? 1.0 - after / before : 0.0;
    rc.heldout_rms_mps2 = n_held > 0 ? std::sqrt(size / n_held) : 0.0;
    rc.p_value = sign_flip_greater(diffs, kSignFlips, 0x0c0e + gi);
    rc.where = describe_peak(rc, sm.sample_weight());
    out.corrections.push_back(std::move(rc));
    if (cv_gain > best_cv) {
      best_cv = cv_gain;
      out.chosen = static_cast<int>(gi);
    }
  }
  if (out.chosen >= 0) {
    const ResidualCorrection& c = out.corrections[static_cast<size_t>(out.chosen)];
    out.unexplained = c.p_value < alpha && c.heldout_gain >= min_gain &&
                      c.heldout_rms_mps2 >= kNegligibleCorrection;
  }
  return out;
}

}  // namespace airtwin::discrepancy_detail
