#include "models/discrepancy_uncertainty.h"

#include <algorithm>
#include <cmath>

#include "common/random_stream.h"
#include "models/discrepancy_fit.h"
#include "models/effect_catalogue.h"

namespace airtwin::discrepancy_detail {
namespace {

// Streams of the analysis's randomness (RandomPurpose::kAnalysis): 0 is the split.
constexpr std::uint64_t kSelectionStream = 1000;
constexpr std::uint64_t kIntervalStream = 2000;

// n indices drawn with replacement from [0, n).
std::vector<size_t> resample(size_t n, RandomStream* rng) {
  std::vector<size_t> pick(n);
  for (size_t& i : pick) {
    i = std::min(n - 1, static_cast<size_t>(rng->uniform() * static_cast<double>(n)));
  }
  return pick;
}

// The q-quantile of sorted values, linear between order statistics.
double quantile(const std::vector<double>& sorted, double q) {
  const double at = q * static_cast<double>(sorted.size() - 1);
  const size_t i = static_cast<size_t>(at);
  if (i + 1 >= sorted.size()) return sorted.back();
  return sorted[i] + (at - static_cast<double>(i)) * (sorted[i + 1] - sorted[i]);
}

// A difference of two typed values; a direction's wraps into (-180, 180].
double typed_difference(const std::string& name, size_t param, double a, double b) {
  double d = a - b;
  if (find_effect(name).id == EffectId::kFloorSlope && param == 1) {
    d = std::remainder(d, 360.0);
  }
  return d;
}

}  // namespace

std::vector<double> selection_frequencies(const WindowFigures& base,
                                          const std::vector<RoundCandidate>& candidates,
                                          const std::vector<double>& held_scale_m,
                                          const std::vector<char>& informative,
                                          const DecisionRule& rule, std::uint64_t seed, int round) {
  std::vector<double> count(candidates.size() + 1, 0.0);
  RandomStream rng(seed, RandomPurpose::kAnalysis,
                   kSelectionStream + static_cast<std::uint64_t>(round));
  DecisionWindows w;
  w.held_scale_m = &held_scale_m;
  w.informative = &informative;
  for (int b = 0; b < kSelectionResamples; ++b) {
    w.train = resample(base.train_cost.size(), &rng);
    w.held = resample(base.held.size(), &rng);
    size_t chosen = candidates.size();  // none
    double best_cost = INFINITY;
    for (size_t c = 0; c < candidates.size(); ++c) {
      const Decision d =
          decide(base, *candidates[c].figures, candidates[c].k, candidates[c].relevant, w, rule);
      if (d.significant && d.delta_bic < best_cost) {
        best_cost = d.delta_bic;
        chosen = c;
      }
    }
    count[chosen] += 1.0;
  }
  for (double& c : count) c /= kSelectionResamples;
  return count;
}

std::vector<std::vector<ParameterInterval>> parameter_intervals(
    const Evaluator& ev, const std::vector<size_t>& train, const ModelExtensions& base,
    const std::vector<std::string>& names, const ModelExtensions& fitted, std::uint64_t seed) {
  std::vector<double> x_hat;
  for (const std::string& name : names) {
    const std::vector<double> fx = fit_from_typed(name, extension_values(fitted, name));
    x_hat.insert(x_hat.end(), fx.begin(), fx.end());
  }
  // The typed values of a refit, name by name.
  auto typed = [&](const std::vector<double>& x) {
    std::vector<std::vector<double>> t;
    const ModelExtensions ext = apply_fit(base, names, x.data());
    for (const std::string& name : names) t.push_back(extension_values(ext, name));
    return t;
  };
  // The same refit on the windows as they are: the centre the resamples spread about (the
  // screening step's bias cancels).
  std::vector<double> x_ref = x_hat;
  polish_fit(ev, train, base, names, kIntervalRefineEvaluations, Fidelity::kScreen, &x_ref);
  const std::vector<std::vector<double>> ref = typed(x_ref);
  const std::vector<std::vector<double>> centre = typed(x_hat);

  std::vector<std::vector<std::vector<double>>> spread(names.size());  // [name][param][resample]
  for (size_t n = 0; n < names.size(); ++n) spread[n].resize(centre[n].size());
  RandomStream rng(seed, RandomPurpose::kAnalysis, kIntervalStream);
  for (int b = 0; b < kIntervalResamples; ++b) {
    const std::vector<size_t> pick = resample(train.size(), &rng);
    std::vector<size_t> windows;
    for (size_t i : pick) windows.push_back(train[i]);
    std::vector<double> x = x_hat;
    polish_fit(ev, windows, base, names, kIntervalRefineEvaluations, Fidelity::kScreen, &x);
    const std::vector<std::vector<double>> t = typed(x);
    for (size_t n = 0; n < names.size(); ++n) {
      for (size_t p = 0; p < t[n].size(); ++p) {
        spread[n][p].push_back(typed_difference(names[n], p, t[n][p], ref[n][p]));
      }
    }
  }
  // The fit's resolution in each typed parameter: the largest change one finest compass step of
  // any fit coordinate makes to it at the fitted values.
  const std::vector<double> finest = fit_finest_steps(names);
  std::vector<std::vector<double>> resolution(names.size());
  for (size_t n = 0; n < names.size(); ++n) resolution[n].assign(centre[n].size(), 0.0);
  for (size_t i = 0; i < x_hat.size(); ++i) {
    std::vector<double> x = x_hat;
    x[i] += finest[i];
    const std::vector<std::vector<double>> t = typed(x);
    for (size_t n = 0; n < names.size(); ++n) {
      for (size_t p = 0; p < t[n].size(); ++p) {
        resolution[n][p] = std::max(resolution[n][p],
                                    std::abs(typed_difference(names[n], p, t[n][p], centre[n][p])));
      }
    }
  }
  std::vector<std::vector<ParameterInterval>> out(names.size());
  for (size_t n = 0; n < names.size(); ++n) {
    for (size_t p = 0; p < spread[n].size(); ++p) {
      std::vector<double>& d = spread[n][p];
      std::sort(d.begin(), d.end());
      const double c = centre[n][p], half = 0.5 * resolution[n][p];
      ParameterInterval iv{c + quantile(d, 0.025), c + quantile(d, 0.975), resolution[n][p]};
      // No finer than the fit can tell: at least the fitted value +- half a finest step.
      iv.lo = std::min(iv.lo, c - half);
      iv.hi = std::max(iv.hi, c + half);
      out[n].push_back(iv);
    }
  }
  return out;
}

}  // namespace airtwin::discrepancy_detail
