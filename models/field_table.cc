#include "models/field_table.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>

#include "common/csv.h"
#include "common/errors.h"
#include "common/units.h"

namespace airtwin {

// Generated at build time from models/data (models/CMakeLists.txt).
extern const char* const kConstructedFieldTableCsv;
extern const char* const kCfdFittedFieldTableCsv;

double FieldCoefficients::speed(double r_m) const {
  // eq. (3)
  return b1 * (std::exp(b2 * r_m) - std::exp(b3 * r_m));
}

FieldTable::FieldTable(std::vector<double> tilts_rad,
                       std::vector<std::array<FieldCoefficients, kAlphaBins>> coefficients)
    : tilts_rad_(std::move(tilts_rad)), coefficients_(std::move(coefficients)) {
  if (tilts_rad_.size() != coefficients_.size()) {
    throw InputError("field table: " + std::to_string(tilts_rad_.size()) + " tilts but " +
                     std::to_string(coefficients_.size()) + " coefficient blocks");
  }
  if (static_cast<int>(tilts_rad_.size()) < kMinTilts) {
    throw InputError("field table: has " + std::to_string(tilts_rad_.size()) +
                     " tilt(s), at least " + std::to_string(kMinTilts) +
                     " are needed for Makima interpolation in tilt");
  }
  for (size_t i = 0; i < tilts_rad_.size(); ++i) {
    const double t = tilts_rad_[i];
    if (!(std::isfinite(t) && t >= 0 && t < kPi / 2)) {
      throw InputError("field table: tilt " + std::to_string(rad_to_deg(t)) +
                       " deg is outside [0, 90)");
    }
    if (i > 0 && !(t > tilts_rad_[i - 1])) {
      throw InputError("field table: tilts must be strictly increasing");
    }
    for (int a = 0; a < kAlphaBins; ++a) {
      const FieldCoefficients& c = coefficients_[i][a];
      if (!(std::isfinite(c.b1) && std::isfinite(c.b2) && std::isfinite(c.b3))) {
        throw InputError("field table: non-finite coefficient at tilt " +
                         std::to_string(rad_to_deg(t)) + " deg, alpha " + std::to_string(a));
      }
    }
  }
}

FieldTable FieldTable::load_csv(const std::string& path) {
  return parse_csv(read_text_file(path), path);
}

FieldTable FieldTable::parse_csv(std::string_view text, const std::string& source) {
  const CsvTable csv = CsvTable::parse(text, source, {"tilt_deg", "alpha_deg", "b1", "b2", "b3"});
  if (csv.rows() == 0) throw InputError(source + ": no data rows after the header");

  // Rows come in contiguous blocks, one per tilt, alpha 0..359 in order within each block.
  std::vector<double> tilts_deg;
  std::vector<std::array<FieldCoefficients, kAlphaBins>> blocks;
  int expected_alpha = 0;
  for (size_t row = 0; row < csv.rows(); ++row) {
    const double tilt = csv.number(row, "tilt_deg");
    const double alpha = csv.number(row, "alpha_deg");
    const FieldCoefficients c{csv.number(row, "b1"), csv.number(row, "b2"), csv.number(row, "b3")};
    if (!(tilt >= 0 && tilt < 90)) {
      throw InputError(csv.where(row) +
                       ": column 'tilt_deg': expected a tilt in [0, 90) deg, got " +
                       csv.text(row, "tilt_deg"));
    }
    const bool new_block = tilts_deg.empty() || tilt != tilts_deg.back();
    if (new_block) {
      if (!tilts_deg.empty() && expected_alpha != kAlphaBins) {
        throw InputError(csv.where(row) + ": tilt " + csv.text(row, "tilt_deg") +
                         " starts before tilt " + std::to_string(tilts_deg.back()) +
                         " is complete (it has alpha 0.." + std::to_string(expected_alpha - 1) +
                         ", expected 0..359)");
      }
      if (!tilts_deg.empty() && !(tilt > tilts_deg.back())) {
        throw InputError(csv.where(row) +
                         ": column 'tilt_deg': tilt blocks must be in increasing "
                         "order without repeats, got " +
                         csv.text(row, "tilt_deg") + " after " + std::to_string(tilts_deg.back()));
      }
      tilts_deg.push_back(tilt);
      blocks.emplace_back();
      expected_alpha = 0;
    }
    if (alpha != expected_alpha) {
      std::string what = expected_alpha >= kAlphaBins
                             ? "tilt " + csv.text(row, "tilt_deg") + " already has alpha 0..359"
                         : alpha < expected_alpha
                             ? "alpha out of order or duplicated"
                             : "alpha " + std::to_string(expected_alpha) + " is missing";
      throw InputError(csv.where(row) + ": column 'alpha_deg': " + what + ", expected " +
                       std::to_string(expected_alpha) + " (whole degrees 0..359 in order), got " +
                       csv.text(row, "alpha_deg"));
    }
    blocks.back()[expected_alpha] = c;
    ++expected_alpha;
  }
  if (expected_alpha != kAlphaBins) {
    throw InputError(source + ": tilt " + std::to_string(tilts_deg.back()) + " ends at alpha " +
                     std::to_string(expected_alpha - 1) + ", expected rows for alpha 0..359");
  }
  std::vector<double> tilts_rad;
  for (double t : tilts_deg) tilts_rad.push_back(deg_to_rad(t));
  try {
    return FieldTable(std::move(tilts_rad), std::move(blocks));
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
}

const FieldTable& FieldTable::constructed_table() {
  static const FieldTable table =
      parse_csv(kConstructedFieldTableCsv,
                "built-in constructed table (models/data/constructed_field_table.csv)");
  return table;
}

const FieldTable& FieldTable::cfd_fitted_table() {
  static const FieldTable table =
      parse_csv(kCfdFittedFieldTableCsv,
                "built-in CFD-fitted table (models/data/cfd_fitted_eq2_field_table.csv)");
  return table;
}

std::string FieldTable::to_csv() const {
  std::string out = "tilt_deg,alpha_deg,b1,b2,b3\n";
  char line[160];
  for (size_t i = 0; i < tilts_rad_.size(); ++i) {
    for (int a = 0; a < kAlphaBins; ++a) {
      const FieldCoefficients& c = coefficients_[i][a];
      std::snprintf(line, sizeof line, "%.10g,%d,%.10g,%.10g,%.10g\n", rad_to_deg(tilts_rad_[i]), a,
                    c.b1, c.b2, c.b3);
      out += line;
    }
  }
  return out;
}

void FieldTable::save_csv(const std::string& path) const {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError(path + ": cannot open file for writing");
  out << to_csv();
  if (!out) throw InputError(path + ": write failed");
}

}  // namespace airtwin
