#include "models/discrepancy_statistics.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "common/random_stream.h"

namespace airtwin::discrepancy_detail {

double bic(double sse, size_t n, int k) {
  const double nn = static_cast<double>(n);
  return nn * std::log(std::max(sse, 1e-300) / nn) + k * std::log(nn);
}

double wilcoxon_greater(const std::vector<double>& d) {
  std::vector<double> nz;
  for (double x : d) {
    if (x != 0.0 && std::isfinite(x)) nz.push_back(x);
  }
  const size_t n = nz.size();
  if (n == 0) return 1.0;
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return std::abs(nz[a]) < std::abs(nz[b]); });
  double w_plus = 0.0, ties = 0.0;
  for (size_t i = 0; i < n;) {
    size_t j = i;
    while (j + 1 < n && std::abs(nz[order[j + 1]]) == std::abs(nz[order[i]])) ++j;
    const double rank = 0.5 * static_cast<double>(i + j) + 1.0;  // average rank of the tie
    for (size_t k = i; k <= j; ++k) {
      if (nz[order[k]] > 0.0) w_plus += rank;
    }
    const double t = static_cast<double>(j - i + 1);
    ties += t * t * t - t;
    i = j + 1;
  }
  const double nn = static_cast<double>(n);
  const double mean = nn * (nn + 1.0) / 4.0;
  const double var = nn * (nn + 1.0) * (2.0 * nn + 1.0) / 24.0 - ties / 48.0;
  if (!(var > 0.0)) return w_plus > mean ? 0.0 : 1.0;
  const double z = (w_plus - mean - 0.5) / std::sqrt(var);
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

double sign_flip_greater(const std::vector<double>& d, int resamples, std::uint64_t seed) {
  if (d.empty()) return 1.0;
  const double observed = std::accumulate(d.begin(), d.end(), 0.0);
  // A flipped sum reaches the observed one up to rounding in the summation order.
  const double tolerance = 1e-12 * std::accumulate(d.begin(), d.end(), 0.0, [](double a, double x) {
                             return a + std::abs(x);
                           });
  RandomStream rng(seed, RandomPurpose::kAnalysis, 0x5f11);
  int reach = 1;  // the observed assignment itself
  for (int r = 0; r < resamples; ++r) {
    double sum = 0.0;
    for (double x : d) sum += rng.uniform() < 0.5 ? -x : x;
    if (sum >= observed - tolerance) ++reach;
  }
  return static_cast<double>(reach) / static_cast<double>(resamples + 1);
}

}  // namespace airtwin::discrepancy_detail
