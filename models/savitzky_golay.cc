#include "models/savitzky_golay.h"

#include <Eigen/Core>
#include <Eigen/QR>
#include <algorithm>

#include "common/errors.h"

namespace airtwin {

std::vector<double> savitzky_golay_weights(int length, int at, int order) {
  AIRTWIN_DEMAND(length >= 1 && at >= 0 && at < length && order >= 0);
  const int degree = std::min(order, length - 1);
  // Vandermonde matrix in the offset from the evaluation point: the fitted polynomial's value
  // there is its constant coefficient, e0^T (A^T A)^-1 A^T x, so the weights are A (A^T A)^-1 e0.
  Eigen::MatrixXd A(length, degree + 1);
  for (int j = 0; j < length; ++j) {
    double power = 1.0;
    for (int c = 0; c <= degree; ++c) {
      A(j, c) = power;
      power *= j - at;
    }
  }
  const Eigen::MatrixXd pinv =
      A.colPivHouseholderQr().solve(Eigen::MatrixXd::Identity(length, length));
  std::vector<double> w(length);
  for (int j = 0; j < length; ++j) w[j] = pinv(0, j);
  return w;
}

std::vector<double> savitzky_golay(std::span<const double> x, int half_window, int order) {
  if (half_window < 0 || order < 0) {
    throw InputError("Savitzky-Golay smoothing: half window and order must be >= 0");
  }
  std::vector<double> y(x.begin(), x.end());
  const int n = static_cast<int>(x.size());
  if (half_window == 0 || n < 2) return y;
  const int length = std::min(n, 2 * half_window + 1);
  // One weight set per position inside the window; interior samples all use the centre one.
  std::vector<std::vector<double>> weights(length);
  for (int i = 0; i < n; ++i) {
    const int lo = std::clamp(i - half_window, 0, n - length);
    const int at = i - lo;
    if (weights[at].empty()) weights[at] = savitzky_golay_weights(length, at, order);
    double sum = 0.0;
    for (int j = 0; j < length; ++j) sum += weights[at][j] * x[lo + j];
    y[i] = sum;
  }
  return y;
}

}  // namespace airtwin
