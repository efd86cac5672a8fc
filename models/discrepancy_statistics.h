#pragma once
// The discrepancy analysis's statistics: the information criterion and the signed-rank test that
// decide whether a candidate cause is significant (models/discrepancy.h, step 2). Internal.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace airtwin::discrepancy_detail {

// BIC of Gaussian errors with n windows and k parameters.
double bic(double sse, size_t n, int k);

// One-sided Wilcoxon signed-rank test that the differences are positive (normal approximation
// with continuity and tie corrections). Zeros are dropped. Returns 1 when nothing is left.
double wilcoxon_greater(const std::vector<double>& d);

// One-sided sign-flip permutation test that the paired differences are positive: the fraction of
// `resamples` random sign assignments (seeded) whose sum reaches the observed sum, counting the
// observed one (so never below 1 / (resamples + 1)). Exact under symmetric differences; more
// powerful than the signed-rank test when a few large differences carry the effect (a cause that
// touches a few windows) among many near zero. Returns 1 when d is empty.
double sign_flip_greater(const std::vector<double>& d, int resamples, std::uint64_t seed);

}  // namespace airtwin::discrepancy_detail
