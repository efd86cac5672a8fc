#include "models/speed_series.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>

#include "common/csv.h"
#include "common/errors.h"

namespace airtwin {

SpeedSeries read_speed_series_csv(const std::string& path) {
  return parse_speed_series_csv(read_text_file(path), path);
}

namespace {

// The checks every series passes, on its columns as read: at least 3 rows, time strictly
// increasing, one sampling interval; counts the negative speeds. where(k) names row k in
// messages, t_text(k) is its time as the user wrote it.
void check_series(SpeedSeries& s, const std::string& source,
                  const std::function<std::string(size_t)>& where,
                  const std::function<std::string(size_t)>& t_text) {
  if (s.size() < 3) {
    throw InputError(source + ": a speed series needs at least 3 rows, got " +
                     std::to_string(s.size()));
  }
  for (size_t row = 0; row < s.size(); ++row) {
    s.n_negative_v += s.v_mps[row] < 0.0 ? 1 : 0;
    s.n_negative_vair += s.vair_mps[row] < 0.0 ? 1 : 0;
    if (row > 0 && !(s.t_s[row] > s.t_s[row - 1])) {
      throw InputError(where(row) + ": column 't': time must increase, got " + t_text(row) +
                       " after " + std::to_string(s.t_s[row - 1]));
    }
  }
  std::vector<double> steps(s.size() - 1);
  for (size_t k = 1; k < s.size(); ++k) steps[k - 1] = s.t_s[k] - s.t_s[k - 1];
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  s.dt_s = sorted[sorted.size() / 2];
  for (size_t k = 0; k < steps.size(); ++k) {
    if (std::abs(steps[k] - s.dt_s) > 0.01 * s.dt_s) {
      throw InputError(where(k + 1) + ": column 't': the series must be uniformly sampled; " +
                       "this step is " + std::to_string(steps[k]) + " s, the series' is " +
                       std::to_string(s.dt_s) + " s (1% tolerance)");
    }
  }
}

}  // namespace

SpeedSeries parse_speed_series_csv(std::string_view text, const std::string& source) {
  const CsvTable csv = CsvTable::parse(text, source, {"t", "v", "vair"});
  SpeedSeries s;
  for (size_t row = 0; row < csv.rows(); ++row) {
    s.t_s.push_back(csv.number(row, "t"));
    s.v_mps.push_back(csv.number(row, "v"));
    s.vair_mps.push_back(csv.number(row, "vair"));
  }
  check_series(
      s, source, [&](size_t row) { return csv.where(row); },
      [&](size_t row) { return csv.text(row, "t"); });
  return s;
}

SpeedSeries make_speed_series(std::vector<double> t_s, std::vector<double> v_mps,
                              std::vector<double> vair_mps, const std::string& source) {
  if (v_mps.size() != t_s.size() || vair_mps.size() != t_s.size()) {
    throw InputError(source + ": t, v and vair must have one value per row, got " +
                     std::to_string(t_s.size()) + ", " + std::to_string(v_mps.size()) + " and " +
                     std::to_string(vair_mps.size()));
  }
  const auto where = [&](size_t row) { return source + ": row " + std::to_string(row); };
  const std::pair<const char*, const std::vector<double>*> columns[] = {
      {"t", &t_s}, {"v", &v_mps}, {"vair", &vair_mps}};
  for (const auto& [name, values] : columns) {
    for (size_t row = 0; row < values->size(); ++row) {
      if (!std::isfinite((*values)[row])) {
        throw InputError(where(row) + ": column '" + name + "': expected a finite number, got " +
                         std::to_string((*values)[row]));
      }
    }
  }
  SpeedSeries s;
  s.t_s = std::move(t_s);
  s.v_mps = std::move(v_mps);
  s.vair_mps = std::move(vair_mps);
  check_series(s, source, where, [&](size_t row) { return std::to_string(s.t_s[row]); });
  return s;
}

}  // namespace airtwin
