#include "models/object_dynamics.h"

#include <cmath>
#include <cstdio>

#include "common/csv.h"
#include "common/errors.h"
#include "models/fast_math.h"

namespace airtwin {

// Generated at build time from models/data/object_types.csv.
extern const char* const kDefaultObjectTypesCsv;

namespace {

bool valid_name(std::string_view name) {
  if (name.empty() || name.size() > 64) return false;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

std::string number_text(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

}  // namespace

void ObjectDynamics::validate(const std::string& where) const {
  if (!(std::isfinite(xi1) && std::isfinite(xi2) && std::isfinite(xi3))) {
    throw InputError(where + ": eq. (8) coefficients must be finite, got xi1 " + number_text(xi1) +
                     ", xi2 " + number_text(xi2) + ", xi3 " + number_text(xi3));
  }
  if (!(xi1 < 0)) {
    throw InputError(where + ": column 'xi1': expected a negative damping (1/s), got " +
                     number_text(xi1));
  }
  if (!(xi2 > 0)) {
    throw InputError(where + ": column 'xi2': expected a positive air-speed gain, got " +
                     number_text(xi2));
  }
  if (!(xi3 <= 0)) {
    throw InputError(where + ": column 'xi3': expected friction <= 0 (m/s^2), got " +
                     number_text(xi3));
  }
}

ObjectTypes ObjectTypes::load_csv(const std::string& path) {
  return parse_csv(read_text_file(path), path);
}

ObjectTypes ObjectTypes::parse_csv(std::string_view text, const std::string& source) {
  const CsvTable csv = CsvTable::parse(text, source, {"object", "xi1", "xi2", "xi3"});
  if (csv.rows() == 0) throw InputError(source + ": no object types after the header");
  ObjectTypes types;
  types.source_ = source;
  for (size_t row = 0; row < csv.rows(); ++row) {
    // Name: a plain identifier, not seen before.
    const std::string& name = csv.text(row, "object");
    if (!valid_name(name)) {
      throw InputError(csv.where(row) +
                       ": column 'object': expected a name of 1-64 characters from "
                       "[A-Za-z0-9_-], got '" +
                       name + "'");
    }
    for (size_t prev = 0; prev < row; ++prev) {
      if (csv.text(prev, "object") == name) {
        throw InputError(csv.where(row) + ": column 'object': duplicate object '" + name +
                         "' (first defined on line " + std::to_string(csv.line_of(prev)) + ")");
      }
    }
    // Coefficients: finite numbers (CsvTable::number) with physical signs.
    const ObjectDynamics xi{csv.number(row, "xi1"), csv.number(row, "xi2"), csv.number(row, "xi3")};
    xi.validate(csv.where(row));
    types.entries_.push_back({name, xi});
  }
  return types;
}

const ObjectTypes& ObjectTypes::defaults() {
  static const ObjectTypes types =
      parse_csv(kDefaultObjectTypesCsv, "built-in object types (models/data/object_types.csv)");
  return types;
}

bool ObjectTypes::contains(std::string_view name) const {
  for (const Entry& e : entries_) {
    if (e.name == name) return true;
  }
  return false;
}

const ObjectDynamics& ObjectTypes::at(std::string_view name) const {
  for (const Entry& e : entries_) {
    if (e.name == name) return e.dynamics;
  }
  std::string known;
  for (const Entry& e : entries_) known += (known.empty() ? "" : ", ") + e.name;
  throw InputError(source_ + ": unknown object '" + std::string(name) + "', known: " + known);
}

namespace {

// Both views of the field expose s, the orientation and coefficients(alpha).
template <typename Field>
Ray ray_of(const Field& field, const Eigen::Vector2d& p_W) {
  Ray ray;
  ray.s_W = field.stagnation_point();
  const Eigen::Vector2d d = p_W - ray.s_W;
  ray.r0 = d.norm();
  if (ray.r0 > 0.0) {
    // alpha is measured from the jet's downstream direction (the pan direction).
    ray.u_W = d / ray.r0;
    ray.radial = 1.0;
    ray.profile = field.coefficients(fast_atan2(d.y(), d.x()) - field.orientation().pan_rad);
  } else {
    // At s: no direction; eq. (3) is 0 at r = 0 for any profile, keep the downstream one.
    ray.profile = field.coefficients(0.0);
  }
  return ray;
}

}  // namespace

Ray ray_through(const OrientedField& field, const Eigen::Vector2d& p_W) {
  return ray_of(field, p_W);
}

Ray ray_through(const OrientedRays& rays, const Eigen::Vector2d& p_W) { return ray_of(rays, p_W); }

PlanarRate moving_rate(const OrientedField& field, const ObjectDynamics& xi,
                       const Eigen::Vector2d& p_W, double v) {
  // eq. (3) via the field model's own evaluation, then eq. (8); eq. (9) without the max.
  const double v_air = field.speed(p_W);
  const Eigen::Vector2d d = p_W - field.stagnation_point();
  const double r = d.norm();
  const Eigen::Vector2d u_W = r > 0.0 ? Eigen::Vector2d(d / r) : Eigen::Vector2d::Zero();
  return {v * u_W, xi.acceleration(v, v_air)};
}

}  // namespace airtwin
