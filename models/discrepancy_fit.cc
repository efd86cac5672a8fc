#include "models/discrepancy_fit.h"

#include <algorithm>
#include <cmath>
#include <unsupported/Eigen/LevenbergMarquardt>

#include "common/errors.h"
#include "common/units.h"
#include "models/effect_catalogue.h"

namespace airtwin::discrepancy_detail {
namespace {

constexpr int kCompassLevels = 4;  // steps of 1/2, 1/4, 1/8 and 1/16 of the grid's pitch
constexpr int kCompassSweeps = 6;  // most moves at one step size
// Grid points scored again at the full step after ranking at the screening step: the ranking
// moves by the screening step's error, which is small against the differences between grid
// points but can swap near-equal neighbours.
constexpr size_t kGridFinalists = 4;
constexpr double kRefineTolerance = 1e-3;
constexpr int kScreenedCompassLevels = 2;  // the compass's levels ranked at the screening step

// One level of a compass search: sweeps of moves by +-step[i] along coordinate first + i of *x,
// each kept when it lowers *x_cost, until a sweep moves nothing (at most kCompassSweeps).
template <typename Cost>
void compass_level(const Cost& cost, const std::vector<double>& step, size_t first,
                   std::vector<double>* x, double* x_cost) {
  for (int sweep = 0, moved = 1; moved && sweep < kCompassSweeps; ++sweep) {
    moved = 0;
    for (size_t i = 0; i < step.size(); ++i) {
      for (const double sign : {1.0, -1.0}) {
        std::vector<double> trial = *x;
        trial[first + i] += sign * step[i];
        const double c = cost(trial);
        if (c < *x_cost) {
          *x_cost = c;
          *x = trial;
          moved = 1;
        }
      }
    }
  }
}

// Levenberg-Marquardt over the training residuals, finite differences in fit coordinates.
struct FitFunctor : Eigen::DenseFunctor<double> {
  FitFunctor(const Evaluator& ev, const std::vector<size_t>& train, const ModelExtensions& base,
             const std::vector<std::string>& names, const std::vector<double>& steps,
             const std::vector<double>& upper, Fidelity fidelity, int n_inputs, int n_values)
      : Eigen::DenseFunctor<double>(n_inputs, n_values),
        ev(ev),
        train(train),
        base(base),
        names(names),
        steps(steps),
        upper(upper),
        fidelity(fidelity) {}

  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& f) const {
    std::vector<WindowScore> scores;
    Eigen::VectorXd r;
    ev.evaluate(apply_fit(base, names, x.data()), train, &scores, &r, fidelity);
    f = r;
    last_x_ = x;
    last_f_ = r;
    ++evaluations;
    return 0;
  }
  // One-sided differences from the residuals at x, which Levenberg-Marquardt has usually just
  // evaluated (kept in `last_`): one prediction of the windows per coordinate, stepping inward at
  // the fit box's upper edge (beyond it apply_fit clamps, and the slope would read 0).
  int df(const Eigen::VectorXd& x, Eigen::MatrixXd& jac) const {
    Eigen::VectorXd f0, fp;
    if (last_x_.size() == x.size() && last_x_ == x) {
      f0 = last_f_;
    } else {
      (*this)(x, f0);
    }
    for (Eigen::Index j = 0; j < x.size(); ++j) {
      Eigen::VectorXd xp = x;
      const size_t k = static_cast<size_t>(j);
      const double h = x[j] + steps[k] <= upper[k] ? steps[k] : -steps[k];
      xp[j] += h;
      (*this)(xp, fp);
      jac.col(j) = (fp - f0) / h;
    }
    return 0;
  }

  const Evaluator& ev;
  const std::vector<size_t>& train;
  const ModelExtensions& base;
  const std::vector<std::string>& names;
  std::vector<double> steps;
  std::vector<double> upper;  // the fit box's upper edges
  Fidelity fidelity;
  mutable int evaluations = 0;
  mutable Eigen::VectorXd last_x_, last_f_;  // the most recent evaluation
};

}  // namespace

int parameter_count(const std::string& name) { return static_cast<int>(fit_box(name).lo.size()); }

FitBox fit_box(const std::string& name) {
  const EffectSpec& spec = find_effect(name);
  FitBox box;
  if (find_effect(name).id == EffectId::kFloorSlope) {
    const double m = spec.params[0].fit_max;
    return {{-m, -m}, {m, m}};
  }
  for (const EffectParameter& p : spec.params) {
    box.lo.push_back(p.fit_min);
    box.hi.push_back(p.fit_max);
  }
  return box;
}

std::vector<double> typed_from_fit(const std::string& name, const double* x) {
  const size_t n = find_effect(name).params.size();
  if (find_effect(name).id == EffectId::kFloorSlope) {
    return {std::hypot(x[0], x[1]), rad_to_deg(std::atan2(x[1], x[0]))};
  }
  return std::vector<double>(x, x + n);
}

std::vector<double> fit_from_typed(const std::string& name, const std::vector<double>& v) {
  if (find_effect(name).id == EffectId::kFloorSlope) {
    const double d = deg_to_rad(v[1]);
    return {v[0] * std::cos(d), v[0] * std::sin(d)};
  }
  return v;
}

std::vector<std::vector<double>> fit_grid(const std::string& name) {
  auto lin = [](double lo, double hi, int n) {
    std::vector<double> v;
    for (int i = 0; i < n; ++i) v.push_back(lo + (hi - lo) * i / (n - 1));
    return v;
  };
  switch (find_effect(name).id) {
    case EffectId::kPressureGradient:
      return {lin(2.0, 30.0, 8), {0.05, 0.1, 0.15, 0.25, 0.4}};
    case EffectId::kResponseDelay:
      return {lin(0.0, 1.5, 13)};
    case EffectId::kFlowDeflection:
      return {lin(-40.0, 40.0, 17)};
    case EffectId::kQuadraticDrag:
      return {lin(0.0, 5.0, 11)};
    case EffectId::kFloorSlope:
      return {lin(-6.0, 6.0, 7), lin(-6.0, 6.0, 7)};
    case EffectId::kStiction:
      return {lin(1.0, 3.0, 41)};  // a threshold: the cost is stepwise
    case EffectId::kNozzleOffset:
      return {lin(-12.0, 12.0, 9), lin(-6.0, 6.0, 7)};
    case EffectId::kFieldScale:
      return {lin(0.4, 2.4, 21)};
    case EffectId::kTransportLag:
      return {lin(0.0, 2.0, 11)};
    case EffectId::kAirLift:
      return {lin(0.0, 0.2, 11)};
    case EffectId::kLinearisedDrag:
      return {lin(0.0, 0.9, 19)};
  }
  AIRTWIN_DEMAND(false);
  return {};
}

ModelExtensions apply_fit(const ModelExtensions& base, const std::vector<std::string>& names,
                          const double* x) {
  ModelExtensions ext = base;
  size_t at = 0;
  for (const std::string& name : names) {
    const FitBox box = fit_box(name);
    std::vector<double> clamped(box.lo.size());
    for (size_t i = 0; i < clamped.size(); ++i) {
      clamped[i] = std::clamp(x[at + i], box.lo[i], box.hi[i]);
    }
    std::vector<double> typed = typed_from_fit(name, clamped.data());
    const EffectSpec& spec = find_effect(name);
    for (size_t i = 0; i < typed.size(); ++i) {
      typed[i] = std::clamp(typed[i], spec.params[i].min, spec.params[i].max);
    }
    set_extension_values(&ext, name, typed);
    at += clamped.size();
  }
  return ext;
}

int refine_fit(const Evaluator& ev, const std::vector<size_t>& train, const ModelExtensions& base,
               const std::vector<std::string>& names, int max_iterations, Eigen::VectorXd* x,
               Fidelity fidelity) {
  // Difference steps of 1/200 of each coordinate's fit range.
  std::vector<double> steps, upper;
  for (const std::string& name : names) {
    const FitBox box = fit_box(name);
    for (size_t i = 0; i < box.lo.size(); ++i) {
      steps.push_back((box.hi[i] - box.lo[i]) / 200.0);
      upper.push_back(box.hi[i]);
    }
  }
  FitFunctor functor(ev, train, base, names, steps, upper, fidelity, static_cast<int>(x->size()),
                     static_cast<int>(ev.residual_count(train)));
  Eigen::LevenbergMarquardt<FitFunctor> lm(functor);
  lm.setMaxfev(max_iterations);
  // Stop when a step changes the cost or the coordinates by less than 1e-3 relative: where
  // objects start and stop the cost is stepwise, and below that Levenberg-Marquardt only spends
  // its budget on the steps' noise.
  lm.setFtol(kRefineTolerance);
  lm.setXtol(kRefineTolerance);
  lm.minimize(*x);
  return functor.evaluations;
}

namespace {

// Per fit coordinate of `names`, the compass's first step: half the grid's pitch.
std::vector<double> first_steps(const std::vector<std::string>& names) {
  std::vector<double> step;
  for (const std::string& name : names) {
    for (const std::vector<double>& axis : fit_grid(name)) {
      step.push_back(axis.size() > 1 ? 0.5 * (axis[1] - axis[0]) : 0.0);
    }
  }
  return step;
}

}  // namespace

std::vector<double> fit_finest_steps(const std::vector<std::string>& names) {
  std::vector<double> step = first_steps(names);
  for (double& h : step) h = std::ldexp(h, 1 - kCompassLevels);
  return step;
}

int polish_fit(const Evaluator& ev, const std::vector<size_t>& train, const ModelExtensions& base,
               const std::vector<std::string>& names, int max_iterations, Fidelity fidelity,
               std::vector<double>* x) {
  std::vector<double> step = first_steps(names);
  AIRTWIN_DEMAND(step.size() == x->size());
  std::vector<WindowScore> scores;
  int evaluations = 0;
  auto cost = [&](const std::vector<double>& at) {
    ev.evaluate(apply_fit(base, names, at.data()), train, &scores, nullptr, fidelity);
    ++evaluations;
    return sum_squares(scores);
  };
  double best = cost(*x);
  for (int level = 0; level < kCompassLevels; ++level) {
    compass_level(cost, step, 0, x, &best);
    for (double& h : step) h *= 0.5;
  }
  if (max_iterations <= 0) return evaluations;
  Eigen::VectorXd xv =
      Eigen::Map<const Eigen::VectorXd>(x->data(), static_cast<Eigen::Index>(x->size()));
  evaluations += refine_fit(ev, train, base, names, max_iterations, &xv, fidelity);
  if (xv.allFinite()) {
    const std::vector<double> refined(xv.data(), xv.data() + xv.size());
    if (cost(refined) < best) *x = refined;
  }
  return evaluations;
}

double fit_ordinary_stiction(const Evaluator& ev, const std::vector<size_t>& train,
                             const ModelExtensions& base) {
  // Ranked at the screening step; the best kGridFinalists scored at the full step.
  std::vector<WindowScore> scores;
  std::vector<std::pair<double, int>> ranked;  // (screening cost, grid index)
  for (int i = 0; i < kOrdinaryStictionGrid; ++i) {
    ModelExtensions ext = base;
    ext.static_friction_ratio = 1.0 + i * kOrdinaryStictionStep;
    ev.evaluate(ext, train, &scores, nullptr, Fidelity::kScreen);
    ranked.emplace_back(sum_squares(scores), i);
  }
  std::sort(ranked.begin(), ranked.end());
  ranked.resize(std::min(ranked.size(), kGridFinalists));
  // In increasing ratio, so that ties keep the smaller ratio.
  std::sort(ranked.begin(), ranked.end(),
            [](const auto& a, const auto& b) { return a.second < b.second; });
  double best_ratio = 1.0, best_cost = INFINITY;
  for (const auto& [screen_cost, i] : ranked) {
    ModelExtensions ext = base;
    ext.static_friction_ratio = 1.0 + i * kOrdinaryStictionStep;
    ev.evaluate(ext, train, &scores, nullptr);
    const double c = sum_squares(scores);
    if (c < best_cost) {
      best_cost = c;
      best_ratio = ext.static_friction_ratio;
    }
  }
  return best_ratio;
}

FitResult fit_extensions(const Evaluator& ev, const std::vector<size_t>& train,
                         const ModelExtensions& base, const std::vector<std::string>& names,
                         std::vector<double> x0, int max_iterations, bool fit_nuisance) {
  FitResult best;
  ModelExtensions on = base;
  std::vector<WindowScore> scores;
  auto cost = [&](const std::vector<double>& x) {
    ev.evaluate(apply_fit(on, names, x.data()), train, &scores, nullptr);
    ++best.evaluations;
    return sum_squares(scores);
  };
  // Grid over the new extension's coordinates; with the nuisance, at the base's ratio and at 1.
  // The grid is ranked at the screening step; its best kGridFinalists are scored at the full one.
  const std::vector<std::vector<double>> grid = fit_grid(names.back());
  const size_t fixed = x0.size();
  std::vector<double> x = x0;
  x.resize(fixed + grid.size());
  std::vector<double> best_x = x;
  double best_ratio = base.static_friction_ratio;
  std::vector<double> ratios{base.static_friction_ratio};
  if (fit_nuisance && base.static_friction_ratio != 1.0) ratios.push_back(1.0);
  struct GridPoint {
    double cost;
    double ratio;
    std::vector<double> x;
  };
  std::vector<GridPoint> points;
  for (const double ratio : ratios) {
    on.static_friction_ratio = ratio;
    std::vector<size_t> idx(grid.size(), 0);
    while (true) {
      for (size_t i = 0; i < grid.size(); ++i) x[fixed + i] = grid[i][idx[i]];
      ev.evaluate(apply_fit(on, names, x.data()), train, &scores, nullptr, Fidelity::kScreen);
      points.push_back({sum_squares(scores), ratio, x});
      size_t d = 0;
      while (d < grid.size() && ++idx[d] == grid[d].size()) idx[d++] = 0;
      if (d == grid.size()) break;
    }
  }
  best.screen_evaluations += static_cast<int>(points.size());
  // Ties keep the earlier point (stable order), as the full-step grid did.
  std::stable_sort(points.begin(), points.end(),
                   [](const GridPoint& a, const GridPoint& b) { return a.cost < b.cost; });
  points.resize(std::min(points.size(), kGridFinalists));
  for (const GridPoint& g : points) {
    on.static_friction_ratio = g.ratio;
    const double c = cost(g.x);
    if (c < best.sse) {
      best.sse = c;
      best_x = g.x;
      best_ratio = g.ratio;
    }
  }
  on.static_friction_ratio = best_ratio;
  // The nuisance under the grid's best point.
  if (fit_nuisance) {
    on.static_friction_ratio =
        fit_ordinary_stiction(ev, train, apply_fit(on, names, best_x.data()));
    best.evaluations += static_cast<int>(std::min<size_t>(kOrdinaryStictionGrid, kGridFinalists));
    best.screen_evaluations += kOrdinaryStictionGrid;
    best.sse = cost(best_x);
  }
  // A compass search below the grid's pitch over the new extension's coordinates: where objects
  // start or stop (static friction, a slope's threshold) the cost is stepwise and
  // Levenberg-Marquardt's finite differences see no slope, which left fits on the grid's points
  // (a 4.5 deg slope fitted as the grid's 4.47 deg toward 243 deg instead of 238). Steps from
  // half the grid's pitch down to a sixteenth of it.
  std::vector<double> step(grid.size(), 0.0);
  for (size_t i = 0; i < grid.size(); ++i) {
    if (grid[i].size() > 1) step[i] = 0.5 * (grid[i][1] - grid[i][0]);
  }
  auto screen_cost = [&](const std::vector<double>& x) {
    ev.evaluate(apply_fit(on, names, x.data()), train, &scores, nullptr, Fidelity::kScreen);
    ++best.screen_evaluations;
    return sum_squares(scores);
  };
  // The coarse levels move by fractions of the grid's pitch: ranked at the screening step, and
  // their end point kept only when the full step agrees that it is better.
  const std::vector<double> grid_x = best_x;
  double level_cost = screen_cost(best_x);
  for (int level = 0; level < kCompassLevels; ++level) {
    const bool screened = level < kScreenedCompassLevels;
    if (level == kScreenedCompassLevels && best_x != grid_x) {
      const double c = cost(best_x);
      if (c < best.sse) {
        best.sse = c;
      } else {
        best_x = grid_x;
      }
    }
    if (level == kScreenedCompassLevels) level_cost = best.sse;
    if (screened) {
      compass_level(screen_cost, step, fixed, &best_x, &level_cost);
    } else {
      compass_level(cost, step, fixed, &best_x, &level_cost);
    }
    if (!screened) best.sse = level_cost;
    for (double& h : step) h *= 0.5;
  }
  // Refine.
  Eigen::VectorXd xv =
      Eigen::Map<const Eigen::VectorXd>(best_x.data(), static_cast<Eigen::Index>(best_x.size()));
  best.evaluations += refine_fit(ev, train, on, names, max_iterations, &xv);
  std::vector<double> refined(xv.data(), xv.data() + xv.size());
  const double c = xv.allFinite() ? cost(refined) : INFINITY;
  if (c < best.sse) {
    best.sse = c;
    best_x = refined;
  }
  best.ext = apply_fit(on, names, best_x.data());
  return best;
}

}  // namespace airtwin::discrepancy_detail
