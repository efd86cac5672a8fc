#include "models/field_grid.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <tuple>

#include "common/csv.h"
#include "common/errors.h"
#include "common/units.h"

namespace airtwin {
namespace {

const std::vector<std::string> kMeasuredColumns = {"pan_deg", "tilt_deg", "x", "y", "speed"};
const std::vector<std::string> kVelocityColumns = {"vx", "vy"};

std::string number_text(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  return buf;
}

// "file.csv:LINE" for a sample read from a file, "label: sample #I" for one built in code.
std::string where(const FieldGrid& grid, size_t index) {
  const size_t line = grid.samples[index].line;
  return line > 0 ? grid.source + ":" + std::to_string(line)
                  : grid.source + ": sample #" + std::to_string(index);
}

// A key that identifies a sample's orientation and position to 1e-9 (deg, m): equal keys are
// the same measurement. Pan is wrapped first, so -180 and 180 deg are the same.
using SampleKey = std::tuple<std::int64_t, std::int64_t, std::int64_t, std::int64_t>;
SampleKey key_of(const FieldSample& s) {
  auto q = [](double v) { return static_cast<std::int64_t>(std::llround(v * 1e9)); };
  return {q(rad_to_deg(wrap_angle(s.orientation.pan_rad))), q(rad_to_deg(s.orientation.tilt_rad)),
          q(s.p_W.x()), q(s.p_W.y())};
}

}  // namespace

void validate_field_grid(const FieldGrid& grid) {
  std::map<SampleKey, size_t> seen;
  for (size_t i = 0; i < grid.samples.size(); ++i) {
    const FieldSample& s = grid.samples[i];
    // Each value within its plausible range, named by its CSV column.
    auto check = [&](double v, bool ok, const char* column, const char* expected, double shown) {
      if (std::isfinite(v) && ok) return;
      throw InputError(where(grid, i) + ": column '" + column + "': expected " + expected +
                       ", got " + number_text(shown));
    };
    const double pan_deg = rad_to_deg(s.orientation.pan_rad);
    const double tilt_deg = rad_to_deg(s.orientation.tilt_rad);
    check(pan_deg, std::abs(pan_deg) <= 360.0, "pan_deg", "a pan in [-360, 360] deg", pan_deg);
    check(tilt_deg, tilt_deg >= 0.0 && tilt_deg < 90.0, "tilt_deg", "a tilt in [0, 90) deg",
          tilt_deg);
    check(s.p_W.x(), std::abs(s.p_W.x()) <= kMaxCoordinateM, "x", "a coordinate within 100 m",
          s.p_W.x());
    check(s.p_W.y(), std::abs(s.p_W.y()) <= kMaxCoordinateM, "y", "a coordinate within 100 m",
          s.p_W.y());
    check(s.speed_mps, s.speed_mps >= 0.0 && s.speed_mps <= kMaxSpeedMps, "speed",
          "an air speed in [0, 1000] m/s", s.speed_mps);
    if (grid.kind == GridKind::kSimulated) {
      check(s.v_W.x(), std::abs(s.v_W.x()) <= kMaxSpeedMps, "vx", "a velocity within 1000 m/s",
            s.v_W.x());
      check(s.v_W.y(), std::abs(s.v_W.y()) <= kMaxSpeedMps, "vy", "a velocity within 1000 m/s",
            s.v_W.y());
    }
    // The same orientation and point twice is a copy-paste slip, not more data.
    const auto [it, inserted] = seen.emplace(key_of(s), i);
    if (!inserted) {
      const FieldSample& first = grid.samples[it->second];
      throw InputError(where(grid, i) + ": duplicate sample (pan " + number_text(pan_deg) +
                       " deg, tilt " + number_text(tilt_deg) + " deg, x " + number_text(s.p_W.x()) +
                       " m, y " + number_text(s.p_W.y()) + " m), first at " +
                       (first.line > 0 ? "line " + std::to_string(first.line)
                                       : "sample #" + std::to_string(it->second)));
    }
  }
}

FieldGrid parse_field_grid(std::string_view text, const std::string& source, GridKind kind) {
  std::vector<std::string> required = kMeasuredColumns;
  if (kind == GridKind::kSimulated) {
    required.insert(required.end(), kVelocityColumns.begin(), kVelocityColumns.end());
  }
  const CsvTable csv = CsvTable::parse(text, source, required);
  if (csv.rows() == 0) throw InputError(source + ": no data rows after the header");

  // Degrees at the edge, radians inside.
  FieldGrid grid;
  grid.source = source;
  grid.kind = kind;
  grid.samples.reserve(csv.rows());
  for (size_t row = 0; row < csv.rows(); ++row) {
    FieldSample s;
    s.orientation.pan_rad = deg_to_rad(csv.number(row, "pan_deg"));
    s.orientation.tilt_rad = deg_to_rad(csv.number(row, "tilt_deg"));
    s.p_W = {csv.number(row, "x"), csv.number(row, "y")};
    s.speed_mps = csv.number(row, "speed");
    if (kind == GridKind::kSimulated) s.v_W = {csv.number(row, "vx"), csv.number(row, "vy")};
    s.line = csv.line_of(row);
    grid.samples.push_back(s);
  }
  validate_field_grid(grid);
  return grid;
}

FieldGrid load_field_grid(const std::string& path, GridKind kind) {
  return parse_field_grid(read_text_file(path), path, kind);
}

std::string field_grid_to_csv(const FieldGrid& grid) {
  const bool velocity = grid.kind == GridKind::kSimulated;
  std::string out =
      velocity ? "pan_deg,tilt_deg,x,y,speed,vx,vy\n" : "pan_deg,tilt_deg,x,y,speed\n";
  char line[256];
  for (const FieldSample& s : grid.samples) {
    int n = std::snprintf(line, sizeof line, "%.12g,%.12g,%.12g,%.12g,%.12g",
                          rad_to_deg(s.orientation.pan_rad), rad_to_deg(s.orientation.tilt_rad),
                          s.p_W.x(), s.p_W.y(), s.speed_mps);
    if (velocity) {
      n += std::snprintf(line + n, sizeof line - static_cast<size_t>(n), ",%.12g,%.12g", s.v_W.x(),
                         s.v_W.y());
    }
    out.append(line, static_cast<size_t>(n));
    out += '\n';
  }
  return out;
}

}  // namespace airtwin
