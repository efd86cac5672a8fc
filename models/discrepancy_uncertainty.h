#pragma once
// How firm the discrepancy analysis's answers are (models/discrepancy.h, step 4), from bootstrap
// resamples of the windows. Internal to the analysis.
//
// - Selection frequency: for each round of the forward selection, the fraction of
//   kSelectionResamples resamples (training and held-out windows drawn with replacement) in which
//   the decision rule (models/discrepancy_decision.h), reading each model's per-window figures,
//   adds each candidate (significant, lowest delta BIC), and the fraction in which it adds
//   none. The fits are held as they are: the frequency says how much a decision rests on which
//   windows happened to be recorded and held out.
// - Parameter intervals: the found causes refitted jointly on kIntervalResamples resamples of the
//   training windows (polish_fit's compass from the fitted values, at the screening step; its
//   finest step, 1/16 of the grid's pitch, is the intervals' resolution), the ordinary static
//   friction held. The 2.5 and 97.5 % quantiles of the refits' differences from the same
//   refit on the windows as they are, added to the fitted value, give the 95 % interval of each
//   typed parameter (a percentile interval, centred on the fit at the full step so that the
//   screening step's bias cancels; directions wrapped). An interval never claims more than the
//   fit can tell: it covers at least the fitted value +- half the finest step (when every
//   refit lands on the same point, the resamples agree within that resolution).

#include <cstdint>
#include <string>
#include <vector>

#include "models/discrepancy_decision.h"
#include "models/discrepancy_evaluation.h"
#include "models/model_extensions.h"

namespace airtwin::discrepancy_detail {

constexpr int kSelectionResamples = 200;
constexpr int kIntervalResamples = 30;
constexpr int kIntervalRefineEvaluations = 0;  // no Levenberg-Marquardt: the compass alone

// One candidate of a round: its figures, parameter count and whether it is larger than
// negligible.
struct RoundCandidate {
  const WindowFigures* figures = nullptr;
  int k = 0;
  bool relevant = false;
};

// Per candidate, then the frequency of "none" last. `round` makes each round's resamples its own.
std::vector<double> selection_frequencies(const WindowFigures& base,
                                          const std::vector<RoundCandidate>& candidates,
                                          const std::vector<double>& held_scale_m,
                                          const std::vector<char>& informative,
                                          const DecisionRule& rule, std::uint64_t seed, int round);

struct ParameterInterval {
  double lo = 0.0, hi = 0.0;
  double resolution = 0.0;  ///< the fit's finest step in this parameter
};

// For each name in `names` (fitted together in `fitted`, on top of `base`), the interval of each
// typed parameter, catalogue order.
std::vector<std::vector<ParameterInterval>> parameter_intervals(
    const Evaluator& ev, const std::vector<size_t>& train, const ModelExtensions& base,
    const std::vector<std::string>& names, const ModelExtensions& fitted, std::uint64_t seed);

}  // namespace airtwin::discrepancy_detail
