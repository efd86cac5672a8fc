#include "models/speed_series.h"

#include <algorithm>
#include <cmath>

#include "common/csv.h"
#include "common/errors.h"

namespace airtwin {

SpeedSeries read_speed_series_csv(const std::string& path) {
  return parse_speed_series_csv(read_text_file(path), path);
}

SpeedSeries parse_speed_series_csv(std::string_view text, const std::string& source) {
  const CsvTable csv = CsvTable::parse(text, source, {"t", "v", "vair"});
  if (csv.rows() < 3) {
    throw InputError(source + ": a speed series needs at least 3 rows, got " +
                     std::to_string(csv.rows()));
  }
  SpeedSeries s;
  for (size_t row = 0; row < csv.rows(); ++row) {
    const double t = csv.number(row, "t"), v = csv.number(row, "v"), va = csv.number(row, "vair");
    s.n_negative_v += v < 0.0 ? 1 : 0;
    s.n_negative_vair += va < 0.0 ? 1 : 0;
    if (!s.t_s.empty() && !(t > s.t_s.back())) {
      throw InputError(csv.where(row) + ": column 't': time must increase, got " +
                       csv.text(row, "t") + " after " + std::to_string(s.t_s.back()));
    }
    s.t_s.push_back(t);
    s.v_mps.push_back(v);
    s.vair_mps.push_back(va);
  }
  std::vector<double> steps(s.size() - 1);
  for (size_t k = 1; k < s.size(); ++k) steps[k - 1] = s.t_s[k] - s.t_s[k - 1];
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  s.dt_s = sorted[sorted.size() / 2];
  for (size_t k = 0; k < steps.size(); ++k) {
    if (std::abs(steps[k] - s.dt_s) > 0.01 * s.dt_s) {
      throw InputError(csv.where(k + 1) + ": column 't': the series must be uniformly sampled; " +
                       "this step is " + std::to_string(steps[k]) + " s, the series' is " +
                       std::to_string(s.dt_s) + " s (1% tolerance)");
    }
  }
  return s;
}

}  // namespace airtwin
