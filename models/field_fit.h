#pragma once
// Appendix C: the eq. (3) coefficient table fitted to air-speed data, fusing a measured grid
// (hot-wire, Appendix A) with a CFD field (Appendix B) by a distance-based weight.
//
// Each sample is placed in its jet's frame with eqs. (1)-(2): s from the sample's own (pan, tilt),
// r = |p - s|, alpha = direction of p - s measured from the pan direction, exactly as
// AirFieldModel evaluates it. For every tilt present in the data, all 360 x 3 coefficients are
// fitted jointly by nonlinear least squares (Eigen's LevenbergMarquardt, sparse Jacobian):
//
//   minimise  sum_i w_i (v_model(r_i, alpha_i) - v_i)^2
//           + sum_{k,j} c^2 (D2 theta_j[k])^2 + sum_{k,j} a^2 (theta_j[k] - theta_j^start)^2
//
// v_model interpolates the coefficients linearly between the two neighbouring 1-degree bins, as
// the model does. Each bin is parameterised by theta = (ln b1, ln(-b2), logit((b2 - b3) / 1000)),
// so every profile stays on the physical branch b1 > 0, b3 < b2 < 0 (zero at s, one peak, decay;
// no sign ambiguity) with b2 - b3 < 1000 1/m. D2 theta_j[k] = theta_j[k-1] - 2 theta_j[k] +
// theta_j[k+1] (around the circle) is the smoothness penalty that keeps directions with few
// samples well-posed; the anchor (a = 1e-4 of the penalty's unit) only pins directions the data
// and the penalty leave free.
//
// Weights. A sample of source S (grid or CFD) at distance r from s weighs w = f_S(r) / N_S,
// N_S = samples of S at that tilt, so each source counts the same however dense it is, and
//   f_cfd(r) = L^2 / (L^2 + r^2),   f_grid(r) = r^2 / (L^2 + r^2)     (L = fusion_length_m):
// CFD alone at s, where the hot-wire is unreliable, the grid dominant far from s, equal weight
// per unit area at r = L when both cover the same area. A tilt with one source only uses w = 1/N.
//
// Penalty scale. c = (smoothing_deg / 2 pi)^2 sqrt(W / 360) v_rms, with W the total weight and
// v_rms the weighted RMS data speed: a relative ripple of a coefficient costs like the same
// relative ripple of the speed, and the penalty equals the data term of one bin for a ripple of
// wavelength smoothing_deg; longer features are fitted, shorter ones smoothed away.
//
// Start. One alpha-independent profile per tilt: a grid search over (b2, b3 = q b2, q > 1) with b1
// by weighted linear least squares, refined by LevenbergMarquardt; every bin starts from it.

#include <limits>
#include <string>
#include <vector>

#include "models/field_grid.h"
#include "models/field_table.h"
#include "models/nozzle_geometry.h"

namespace airtwin {

struct FieldFitOptions {
  NozzleGeometry geometry;          ///< eqs. (1)-(2): where s is for each sample's orientation
  double fusion_length_m = 0.3;     ///< L: CFD and grid weigh equally at r = L (m)
  double smoothing_deg = 20.0;      ///< ripples shorter than this (deg) are smoothed, longer fitted
  double mape_min_speed_mps = 0.1;  ///< MAPE counts data speeds >= this (hot-wire limit), m/s
  int max_evaluations = 200;        ///< LevenbergMarquardt function evaluations per tilt
  /// Wall-clock budget per tilt (s); a fit that runs out keeps its best answer so far and reports
  /// lm_converged = false. Data that fit eq. (3) converge in a few seconds at most.
  double time_budget_s = 30.0;
  int threads = 0;  ///< tilts fitted concurrently; 0: one per hardware thread

  /// Throws InputError naming the option when a value is out of range.
  void validate() const;
};

/// Minimum samples a source must have at a tilt it covers (a 4 x 4 grid).
inline constexpr size_t kMinSamplesPerTilt = 16;

/// Fusion share of the CFD at distance r (m) from s: L^2 / (L^2 + r^2); the grid's is 1 minus it.
double cfd_fusion_share(double r_m, double fusion_length_m);

/// Agreement of the fitted model with one source at one tilt.
struct SourceFitStats {
  size_t n_samples = 0;       ///< samples of the source at the tilt
  size_t n_mape_samples = 0;  ///< of which data speed >= mape_min_speed_mps
  /// mean |v_model - v| / v * 100 over those (NaN when none)
  double mape_pct = std::numeric_limits<double>::quiet_NaN();
  double rmse_mps = std::numeric_limits<double>::quiet_NaN();  ///< over all samples (NaN if none)
};

/// The fit of one tilt.
struct TiltFitReport {
  double tilt_rad = 0.0;
  SourceFitStats grid, cfd;
  /// Mean angle (deg) between the CFD velocity and the model's radial direction (p - s), over CFD
  /// samples with |v_xy| >= mape_min_speed_mps and p != s (NaN when none).
  double cfd_direction_error_deg = std::numeric_limits<double>::quiet_NaN();
  size_t n_direction_samples = 0;
  int alpha_bins_with_data = 0;     ///< 1-degree directions holding at least one sample
  FieldCoefficients start_profile;  ///< the alpha-independent starting profile
  int lm_iterations = 0;
  int lm_evaluations = 0;
  std::string lm_status;      ///< Eigen's termination reason, in words
  bool lm_converged = false;  ///< false when the evaluation or time budget ran out
};

struct FieldFitResult {
  FieldTable table;                  ///< one block per tilt, in increasing tilt
  std::vector<TiltFitReport> tilts;  ///< same order
};

/// Fits the coefficient table to a measured grid and, optionally, a CFD grid (`cfd` may be null).
/// Tilts are the distinct tilts of both sources together (equal to 1e-6 deg); at least
/// FieldTable::kMinTilts are needed, and a source covering a tilt needs kMinSamplesPerTilt samples
/// there. Throws InputError naming the file for too few tilts or samples, an invalid sample
/// (validate_field_grid), a grid of the wrong kind, or an invalid option. Deterministic.
FieldFitResult fit_field_table(const FieldGrid& grid, const FieldGrid* cfd,
                               const FieldFitOptions& options);

/// The agreement of a given table with the grids, measured as fit_field_table measures its own
/// fit (MAPE, RMSE, CFD direction) but without fitting: one report per distinct tilt of the
/// samples (equal to 1e-6 deg), in increasing tilt, the model evaluated at each sample's own
/// orientation (Makima between the table's tilts, so any tilt the table reaches). The optimiser
/// fields, start_profile and alpha_bins_with_data stay empty (lm_status "not fitted"). `grid` or
/// `cfd` may be null, not both. Throws InputError naming the file for an invalid sample or a grid
/// of the wrong kind, and for an invalid option or geometry.
std::vector<TiltFitReport> evaluate_field_table(const FieldTable& table, const FieldGrid* grid,
                                                const FieldGrid* cfd,
                                                const FieldFitOptions& options);

}  // namespace airtwin
