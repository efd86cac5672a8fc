#pragma once
// The discrepancy analysis's last step (models/discrepancy.h, step 5): is the residual that the
// causes found leave still structured? A structure the catalogue does not name (a patch of floor
// with more friction, a pulsing jet, a swirl that grows away from s) shows as a residual
// acceleration that depends on where or when the object moves.
//
// At each sample with two samples either side, a local quadratic through the 5 positions gives
// the measured acceleration; the model is started from the quadratic's state at the first of
// them and the same quadratic through its positions gives the model's: the same estimator on
// both, so that its bias (the motion is not quadratic over 0.2 s) cancels. Samples where neither
// moves are left out. The difference, split along the radial direction from s and across it, is
// smoothed over each feature group by a Gaussian kernel smoother on a grid (Nadaraya-Watson,
// shrunk toward zero where the data are thin), its bandwidth chosen by 5-fold cross-validation
// over the training windows. The group with the best cross-validated gain is then tested once on
// the held-out windows: the mean loss of each window's samples with and without the correction,
// compared by a one-sided sign-flip permutation test over windows (the windows are independent,
// the samples inside one are not; a patch of floor touches a few windows strongly, which the sum
// of the differences weighs and their ranks would not).
//
// Speed is not a group: the catalogue's quadratic drag covers a speed dependence, and the
// measured speed carries the turbulence's gust (a gust both speeds an object up and keeps pushing
// it), which a smoother over it would read as structure. Internal to the analysis.

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "models/discrepancy.h"
#include "models/discrepancy_windows.h"
#include "models/extended_predictor.h"
#include "models/model_extensions.h"

namespace airtwin::discrepancy_detail {

struct CorrectionOutcome {
  std::vector<ResidualCorrection> corrections;  // one per feature group
  int chosen = -1;                              // best cross-validated gain; -1: none positive
  size_t n_samples = 0;                         // samples with an acceleration estimate
  // The training samples' median residual (radial, across; m/s^2), taken out before smoothing.
  Eigen::Vector2d median_residual = Eigen::Vector2d::Zero();
  bool unexplained = false;  // the chosen one passes on the held-out windows
};

// The nonparametric correction of the residual of `ext` on the windows of `ws`, fitted on
// `train` and tested on `held` at level `alpha` and minimal held-out gain `min_gain`.
CorrectionOutcome correct_residual(const ExtendedPredictor& predictor, const WindowSet& ws,
                                   const ModelExtensions& ext, const std::vector<size_t>& train,
                                   const std::vector<size_t>& held, double alpha, double min_gain);

}  // namespace airtwin::discrepancy_detail
