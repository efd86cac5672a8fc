#pragma once
// The coefficient table of eq. (3): v_air(r) = b1 (exp(b2 r) - exp(b3 r)) along each radial
// direction alpha from the stagnation point, one (b1, b2, b3) per alpha (1 degree apart, 0..359)
// and per fitted tilt phi.
//
// alpha is measured counter-clockwise from the jet's downstream direction (origin -> c; for
// phi = 0 the pan direction). File format (docs/data_formats.md): CSV with header
// `tilt_deg,alpha_deg,b1,b2,b3`, b1 in m/s, b2 and b3 in 1/m; one block of 360 rows per tilt,
// alpha = 0, 1, ..., 359 in order, tilts increasing, at least 3 tilts (Makima in tilt).

#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace airtwin {

/// One radial profile of eq. (3).
struct FieldCoefficients {
  double b1 = 0.0;  ///< m/s
  double b2 = 0.0;  ///< 1/m
  double b3 = 0.0;  ///< 1/m

  /// eq. (3): air speed (m/s) at distance r (m) from the stagnation point.
  double speed(double r_m) const;
};

class FieldTable {
 public:
  static constexpr int kAlphaBins = 360;  ///< alpha resolution: 1 degree
  static constexpr int kMinTilts = 3;

  /// `coefficients[i][a]` is the profile at tilt `tilts_rad[i]` and alpha = a degrees.
  /// Throws InputError when tilts are fewer than kMinTilts, not strictly increasing, outside
  /// [0, 90) deg, or a coefficient is not finite.
  FieldTable(std::vector<double> tilts_rad,
             std::vector<std::array<FieldCoefficients, kAlphaBins>> coefficients);

  /// Reads and validates a table file; every problem is an InputError naming file, line, column.
  static FieldTable load_csv(const std::string& path);
  /// Same, from text in memory; `source` names it in messages.
  static FieldTable parse_csv(std::string_view text, const std::string& source);
  /// The table constructed from the wall-jet literature for the paper's jet
  /// (models/data/constructed_field_table.csv, `airtwin maketable`; compiled into the binary).
  static const FieldTable& constructed_table();
  /// eq. (3)'s table fitted to the jet's CFD the paper's way, for eq. (2) refitted to it
  /// (models/data/cfd_fitted_eq2_field_table.csv, docs/cfd.md; compiled into the binary).
  static const FieldTable& cfd_fitted_table();

  /// The CSV text of this table (deterministic formatting: same table, same bytes).
  std::string to_csv() const;
  /// Writes to_csv() to `path`; throws InputError when the file cannot be written.
  void save_csv(const std::string& path) const;

  const std::vector<double>& tilts_rad() const { return tilts_rad_; }
  size_t n_tilts() const { return tilts_rad_.size(); }
  const FieldCoefficients& at(size_t tilt_index, int alpha_deg) const {
    return coefficients_[tilt_index][alpha_deg];
  }

 private:
  std::vector<double> tilts_rad_;
  std::vector<std::array<FieldCoefficients, kAlphaBins>> coefficients_;
};

}  // namespace airtwin
