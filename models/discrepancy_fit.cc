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

// Levenberg-Marquardt over the training residuals, central differences in fit coordinates.
struct FitFunctor : Eigen::DenseFunctor<double> {
  FitFunctor(const Evaluator& ev, const std::vector<size_t>& train, const ModelExtensions& base,
             const std::vector<std::string>& names, const std::vector<double>& steps, int n_inputs,
             int n_values)
      : Eigen::DenseFunctor<double>(n_inputs, n_values),
        ev(ev),
        train(train),
        base(base),
        names(names),
        steps(steps) {}

  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& f) const {
    std::vector<WindowScore> scores;
    Eigen::VectorXd r;
    ev.evaluate(apply_fit(base, names, x.data()), train, &scores, &r);
    f = r;
    ++evaluations;
    return 0;
  }
  int df(const Eigen::VectorXd& x, Eigen::MatrixXd& jac) const {
    Eigen::VectorXd fp, fm;
    for (Eigen::Index j = 0; j < x.size(); ++j) {
      Eigen::VectorXd xp = x, xm = x;
      xp[j] += steps[static_cast<size_t>(j)];
      xm[j] -= steps[static_cast<size_t>(j)];
      (*this)(xp, fp);
      (*this)(xm, fm);
      jac.col(j) = (fp - fm) / (2.0 * steps[static_cast<size_t>(j)]);
    }
    return 0;
  }

  const Evaluator& ev;
  const std::vector<size_t>& train;
  const ModelExtensions& base;
  const std::vector<std::string>& names;
  std::vector<double> steps;
  mutable int evaluations = 0;
};

}  // namespace

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
               const std::vector<std::string>& names, int max_iterations, Eigen::VectorXd* x) {
  // Central-difference steps of 1/200 of each coordinate's fit range.
  std::vector<double> steps;
  for (const std::string& name : names) {
    const FitBox box = fit_box(name);
    for (size_t i = 0; i < box.lo.size(); ++i) steps.push_back((box.hi[i] - box.lo[i]) / 200.0);
  }
  FitFunctor functor(ev, train, base, names, steps, static_cast<int>(x->size()),
                     static_cast<int>(ev.residual_count(train)));
  Eigen::LevenbergMarquardt<FitFunctor> lm(functor);
  lm.setMaxfev(max_iterations);
  lm.minimize(*x);
  return functor.evaluations;
}

double fit_ordinary_stiction(const Evaluator& ev, const std::vector<size_t>& train,
                             const ModelExtensions& base) {
  std::vector<WindowScore> scores;
  double best_ratio = 1.0, best_cost = INFINITY;
  for (int i = 0; i < kOrdinaryStictionGrid; ++i) {
    ModelExtensions ext = base;
    ext.static_friction_ratio = 1.0 + i * kOrdinaryStictionStep;
    ev.evaluate(ext, train, &scores, nullptr);
    const double c = sum_squares(scores);
    if (c < best_cost) {  // ties keep the smaller ratio
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
  const std::vector<std::vector<double>> grid = fit_grid(names.back());
  const size_t fixed = x0.size();
  std::vector<double> x = x0;
  x.resize(fixed + grid.size());
  std::vector<double> best_x = x;
  std::vector<double> ratios{base.static_friction_ratio};
  if (fit_nuisance && base.static_friction_ratio != 1.0) ratios.push_back(1.0);
  for (const double ratio : ratios) {
    on.static_friction_ratio = ratio;
    std::vector<size_t> idx(grid.size(), 0);
    while (true) {
      for (size_t i = 0; i < grid.size(); ++i) x[fixed + i] = grid[i][idx[i]];
      const double c = cost(x);
      if (c < best.sse) {
        best.sse = c;
        best_x = x;
      }
      size_t d = 0;
      while (d < grid.size() && ++idx[d] == grid[d].size()) idx[d++] = 0;
      if (d == grid.size()) break;
    }
  }
  // The nuisance under the grid's best point.
  if (fit_nuisance) {
    on.static_friction_ratio =
        fit_ordinary_stiction(ev, train, apply_fit(on, names, best_x.data()));
    best.evaluations += kOrdinaryStictionGrid;
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
  for (int level = 0; level < kCompassLevels; ++level) {
    for (int sweep = 0, moved = 1; moved && sweep < kCompassSweeps; ++sweep) {
      moved = 0;
      for (size_t i = 0; i < grid.size(); ++i) {
        for (const double sign : {1.0, -1.0}) {
          std::vector<double> trial = best_x;
          trial[fixed + i] += sign * step[i];
          const double c = cost(trial);
          if (c < best.sse) {
            best.sse = c;
            best_x = trial;
            moved = 1;
          }
        }
      }
    }
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
