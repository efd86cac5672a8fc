#pragma once
// Quantiles of a sample, as the batch report and its plots state them: linear interpolation
// between the order statistics (Hyndman & Fan's type 7, numpy's and R's default): for n sorted
// values v[0..n-1], q(p) = v[h] + (h - floor h) (v[floor h + 1] - v[floor h]) with h = (n - 1) p.
// q(0) is the smallest value, q(1) the largest, q(0.5) the usual median.

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/errors.h"

namespace airtwin {

/// The p-quantile (0 <= p <= 1) of `sorted` (ascending, non-empty); AIRTWIN_DEMAND otherwise.
inline double quantile_of_sorted(const std::vector<double>& sorted, double p) {
  AIRTWIN_DEMAND(!sorted.empty() && p >= 0.0 && p <= 1.0);
  const double h = static_cast<double>(sorted.size() - 1) * p;
  const size_t lo = static_cast<size_t>(std::floor(h));
  if (lo + 1 >= sorted.size()) return sorted.back();
  return sorted[lo] + (h - static_cast<double>(lo)) * (sorted[lo + 1] - sorted[lo]);
}

/// The p-quantile of `values` in any order (non-empty).
inline double quantile(std::vector<double> values, double p) {
  std::sort(values.begin(), values.end());
  return quantile_of_sorted(values, p);
}

}  // namespace airtwin
