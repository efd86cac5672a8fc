#pragma once
// A speed series: data that already are speeds, for `airtwin identify --series`.
//
// CSV with header `t,v,vair` (any column order): t in s, uniformly sampled; v the object's speed
// and vair the air speed at the object, both in m/s. Speeds are magnitudes (eq. 9), but measured
// ones are not: a finite-difference or projected speed of a resting object is negative about half
// of the time. Negative values are data; they are counted, not refused.
// One series per file. `#` comments and blank lines are allowed (common/csv.h).

#include <string>
#include <string_view>
#include <vector>

namespace airtwin {

struct SpeedSeries {
  std::vector<double> t_s, v_mps, vair_mps;
  double dt_s = 0.0;                             ///< the uniform sampling interval read from t
  size_t n_negative_v = 0, n_negative_vair = 0;  ///< measured values below zero
  size_t size() const { return t_s.size(); }
};

/// Reads and validates: header, finite numbers, t strictly increasing with one
/// interval (every step within 1% of the median step), at least 3 rows. Every problem is an
/// InputError naming the file, the line and the column.
SpeedSeries read_speed_series_csv(const std::string& path);
/// Same, from text in memory; `source` names it in messages.
SpeedSeries parse_speed_series_csv(std::string_view text, const std::string& source);
/// Same, from columns in memory (t in s, v and vair in m/s, of equal lengths; NaN and infinity
/// refused): the reader's checks, messages naming `source` and the row index from 0.
SpeedSeries make_speed_series(std::vector<double> t_s, std::vector<double> v_mps,
                              std::vector<double> vair_mps, const std::string& source);

}  // namespace airtwin
