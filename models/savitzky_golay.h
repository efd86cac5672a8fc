#pragma once
// Savitzky-Golay smoothing of a uniformly sampled series: each sample is replaced by the value at
// its own time of the least-squares polynomial of degree `order` through the samples within
// +-half_window. Near the ends the window keeps its length and shifts inward (the polynomial is
// evaluated off-centre), so no sample is dropped and no padding is invented; a series shorter
// than the window uses all of its samples and a degree of at most its length - 1.
//
// Why it is here: SINDy's discrete-time regression puts the measured speed v_k in the regressors.
// Noise there attenuates the fitted coefficients (errors in variables: 5% speed noise moves the
// tracer's xi1 by ~12%), and bisquare weighting cannot help because the noise is not an outlier.
// A cubic over 9 samples (0.2 s at 40 Hz) follows the object's speed, whose time constant is
// 1/|xi1| = 0.24-0.38 s, to ~1e-4 relative, and passes ~26% of white noise's variance at the
// centre (Savitzky & Golay 1964; variance factor 3(3m^2 + 3m - 1) / ((2m-1)(2m+1)(2m+3)), m = 4).

#include <span>
#include <vector>

namespace airtwin {

/// Smooths `x` (uniform sampling assumed). half_window >= 1, order >= 0; half_window 0 returns
/// `x` unchanged. Throws InputError for negative arguments.
std::vector<double> savitzky_golay(std::span<const double> x, int half_window, int order);

/// The weights w such that sum_j w[j] x[lo + j] is the smoothed value at sample lo + at, for a
/// window of `length` samples starting at lo and a polynomial degree of at most `order`.
std::vector<double> savitzky_golay_weights(int length, int at, int order);

}  // namespace airtwin
