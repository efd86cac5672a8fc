#pragma once
// The discrepancy analysis's statistics: the information criterion and the signed-rank test that
// decide whether a candidate cause is significant (models/discrepancy.h, step 2). Internal.

#include <cstddef>
#include <vector>

namespace airtwin::discrepancy_detail {

// BIC of Gaussian errors with n windows and k parameters.
double bic(double sse, size_t n, int k);

// One-sided Wilcoxon signed-rank test that the differences are positive (normal approximation
// with continuity and tie corrections). Zeros are dropped. Returns 1 when nothing is left.
double wilcoxon_greater(const std::vector<double>& d);

}  // namespace airtwin::discrepancy_detail
