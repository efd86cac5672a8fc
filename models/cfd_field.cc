#include "models/cfd_field.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/errors.h"
#include "common/units.h"
#include "models/json_file.h"

namespace airtwin {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr const char* kFormat = "airtwin-cfd-floor 1";

long count(const Json& j, const std::string& key, const std::string& where) {
  const Json& v = json_member(j, key, where);
  if (!v.is_number_integer() || v.get<long>() < 2) {
    throw InputError(where + ": field '" + key + "' must be an integer >= 2");
  }
  return v.get<long>();
}

}  // namespace

CfdCase CfdCase::read(const std::string& header_path) {
  static_assert(std::endian::native == std::endian::little, "the CFD data are little-endian");
  const Json h = read_json_file(header_path);
  const std::string& where = header_path;
  const Json& format = json_member(h, "format", where);
  if (!format.is_string() || format.get<std::string>() != kFormat) {
    throw InputError(where + ": format: expected \"" + std::string(kFormat) + "\"");
  }
  CfdCase c;
  c.name_ = json_member(h, "case", where).is_string() ? h["case"].get<std::string>() : "";
  const double tilt_deg = json_number(h, "tilt_deg", where);
  if (!(tilt_deg >= 0.0 && tilt_deg < 90.0)) {
    throw InputError(where + ": tilt_deg must be in [0, 90), got " + std::to_string(tilt_deg));
  }
  c.tilt_rad_ = deg_to_rad(tilt_deg);
  c.held_out_ = json_member(h, "held_out", where).is_boolean() && h["held_out"].get<bool>();
  c.mesh_level_ = static_cast<int>(json_number(h, "mesh_level", where));
  c.inlet_d_m_ = json_number(json_member(h, "inlet", where), "diameter_m", where + ": inlet");
  const Json& s = json_member(h, "stagnation_point_s_m", where);
  if (!s.is_array() || s.size() != 2 || !s[0].is_number()) {
    throw InputError(where + ": stagnation_point_s_m must be [x, y] in metres");
  }
  c.s_x_m_ = s[0].get<double>();
  const Json& ambient = json_member(h, "ambient", where);
  c.k_ambient_ = json_number(ambient, "k_m2_s2", where + ": ambient");
  c.epsilon_ambient_ = json_number(ambient, "epsilon_m2_s3", where + ": ambient");

  const std::string gw = where + ": grid";
  const Json& g = json_member(h, "grid", where);
  c.x0_m_ = json_number(g, "x0_m", gw);
  c.dx_m_ = json_number(g, "dx_m", gw);
  c.nx_ = count(g, "nx", gw);
  c.y0_m_ = json_number(g, "y0_m", gw);
  c.dy_m_ = json_number(g, "dy_m", gw);
  c.ny_ = count(g, "ny", gw);
  if (!(c.dx_m_ > 0.0 && c.dy_m_ > 0.0)) throw InputError(gw + ": dx_m and dy_m must be > 0");
  for (const Json& z : json_member(g, "heights_m", gw)) {
    if (!z.is_number() || !(z.get<double>() > 0.0)) {
      throw InputError(gw + ": heights_m must be positive numbers");
    }
    c.heights_m_.push_back(z.get<double>());
  }
  if (c.heights_m_.empty() || !std::is_sorted(c.heights_m_.begin(), c.heights_m_.end())) {
    throw InputError(gw + ": heights_m must be a non-empty increasing list");
  }
  const Json& fields = json_member(h, "fields", where);
  std::map<std::string, int> index;
  for (size_t i = 0; i < fields.size(); ++i) {
    if (fields[i].is_string()) index[fields[i].get<std::string>()] = static_cast<int>(i);
  }
  for (const char* needed : {"ux", "uy", "uz", "k", "epsilon", "p"}) {
    if (!index.count(needed)) {
      throw InputError(where + ": fields: no '" + std::string(needed) + "' among them");
    }
  }
  c.n_fields_ = static_cast<int>(fields.size());
  const int uz = index["uz"];
  c.ux_ = index["ux"];
  c.uy_ = index["uy"];
  c.k_ = index["k"];
  c.epsilon_ = index["epsilon"];
  const Json& dtype = json_member(h, "dtype", where);
  const Json& order = json_member(h, "byte_order", where);
  if (dtype != "float32" || order != "little") {
    throw InputError(where + ": expected dtype float32 and byte_order little");
  }

  // The data: [height][field][iy][ix] float32, little-endian.
  const Json& file = json_member(h, "data_file", where);
  if (!file.is_string()) throw InputError(where + ": data_file must be a file name");
  const std::string data_path =
      (fs::path(header_path).parent_path() / file.get<std::string>()).string();
  const size_t n = c.heights_m_.size() * static_cast<size_t>(c.n_fields_) *
                   static_cast<size_t>(c.ny_) * static_cast<size_t>(c.nx_);
  std::ifstream d(data_path, std::ios::binary);
  if (!d) throw InputError(data_path + ": cannot open (named by " + header_path + ")");
  std::error_code ec;
  const auto size = fs::file_size(data_path, ec);
  if (ec || size != n * sizeof(float)) {
    throw InputError(data_path + ": expected " + std::to_string(n * sizeof(float)) +
                     " bytes (the header's grid), found " + (ec ? "none" : std::to_string(size)));
  }
  std::vector<float> raw(n);
  d.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(n * sizeof(float)));
  if (!d) throw InputError(data_path + ": cannot read");
  // Repacked node by node, the four fields the air needs side by side: one lookup touches four
  // 16-byte nodes per height instead of sixteen scattered floats; uz in a plane of its own (only
  // the simulated anemometer reads it) and the pressure in another (only the pressure push near s
  // reads it). Slots 4 and 5 of `wanted` are uz and p.
  const size_t nodes_per_height = static_cast<size_t>(c.ny_) * static_cast<size_t>(c.nx_);
  const int wanted[6] = {c.ux_, c.uy_, c.k_, c.epsilon_, uz, index["p"]};
  const char* wanted_name[6] = {"ux", "uy", "k", "epsilon", "uz", "p"};
  c.nodes_.resize(c.heights_m_.size() * nodes_per_height);
  c.uz_.resize(c.heights_m_.size() * nodes_per_height);
  c.p_.resize(c.heights_m_.size() * nodes_per_height);
  for (size_t h = 0; h < c.heights_m_.size(); ++h) {
    for (int f = 0; f < 6; ++f) {
      const float* plane =
          raw.data() + (h * static_cast<size_t>(c.n_fields_) + static_cast<size_t>(wanted[f])) *
                           nodes_per_height;
      for (size_t i = 0; i < nodes_per_height; ++i) {
        if (!std::isfinite(plane[i])) {
          throw InputError(data_path + ": " + wanted_name[f] + " at height " +
                           std::to_string(c.heights_m_[h]) + " m, node (ix " +
                           std::to_string(i % static_cast<size_t>(c.nx_)) + ", iy " +
                           std::to_string(i / static_cast<size_t>(c.nx_)) + ") is not finite");
        }
        const size_t node = h * nodes_per_height + i;
        if (f < 4) {
          c.nodes_[node][f] = plane[i];
        } else {
          (f == 4 ? c.uz_ : c.p_)[node] = plane[i];
        }
      }
    }
  }
  // The pressure's reach from s at the lowest height: the farthest node above 1 % of the peak.
  float p_max = 0.0f;
  for (size_t i = 0; i < nodes_per_height; ++i) p_max = std::max(p_max, c.p_[i]);
  for (size_t i = 0; i < nodes_per_height; ++i) {
    if (p_max > 0.0f && c.p_[i] > 0.01f * p_max) {
      const double x = c.x0_m_ + static_cast<double>(i % static_cast<size_t>(c.nx_)) * c.dx_m_;
      const double y = c.y0_m_ + static_cast<double>(i / static_cast<size_t>(c.nx_)) * c.dy_m_;
      c.pressure_radius_m_ = std::max(c.pressure_radius_m_, std::hypot(x - c.s_x_m_, y));
    }
  }
  return c;
}

void CfdCase::accumulate(double x_m, double y_abs_m, size_t lo, double t, double weight,
                         double acc[4]) const {
  const double fx = (x_m - x0_m_) / dx_m_, fy = (y_abs_m - y0_m_) / dy_m_;
  if (!(fx >= 0.0 && fy >= 0.0 && fx <= static_cast<double>(nx_ - 1) &&
        fy <= static_cast<double>(ny_ - 1))) {
    acc[2] += weight * k_ambient_;  // still air outside the grid
    acc[3] += weight * epsilon_ambient_;
    return;
  }
  const long ix = std::min(static_cast<long>(fx), nx_ - 2);
  const long iy = std::min(static_cast<long>(fy), ny_ - 2);
  const double tx = fx - static_cast<double>(ix), ty = fy - static_cast<double>(iy);
  const double w00 = (1.0 - ty) * (1.0 - tx), w10 = (1.0 - ty) * tx, w01 = ty * (1.0 - tx),
               w11 = ty * tx;
  const size_t plane = static_cast<size_t>(ny_) * static_cast<size_t>(nx_);
  const Node* row0 = nodes_.data() + lo * plane +
                     static_cast<size_t>(iy) * static_cast<size_t>(nx_) + static_cast<size_t>(ix);
  const Node* row1 = row0 + nx_;
  const double wl = weight * (1.0 - t);
  for (int f = 0; f < 4; ++f) {
    acc[f] += wl * (w00 * row0[0][f] + w10 * row0[1][f] + w01 * row1[0][f] + w11 * row1[1][f]);
  }
  if (t > 0.0) {
    const Node* up0 = row0 + plane;
    const Node* up1 = up0 + nx_;
    const double wu = weight * t;
    for (int f = 0; f < 4; ++f) {
      acc[f] += wu * (w00 * up0[0][f] + w10 * up0[1][f] + w01 * up1[0][f] + w11 * up1[1][f]);
    }
  }
}

std::pair<size_t, double> CfdCase::height_bracket(double z_m) const {
  if (z_m >= heights_m_.back()) return {heights_m_.size() - 1, 0.0};
  if (!(z_m > heights_m_.front())) return {0, 0.0};
  size_t lo = 0;
  while (heights_m_[lo + 1] < z_m) ++lo;
  return {lo, (z_m - heights_m_[lo]) / (heights_m_[lo + 1] - heights_m_[lo])};
}

CfdSample CfdCase::at(double x_m, double y_m, double z_m) const {
  const auto [lo, t] = height_bracket(z_m);
  double acc[4] = {0.0, 0.0, 0.0, 0.0};
  accumulate(x_m, std::abs(y_m), lo, t, 1.0, acc);
  CfdSample out;
  out.u_W = {acc[0], y_m < 0.0 ? -acc[1] : acc[1]};  // the mirror image for y < 0
  out.k = acc[2];
  out.epsilon = acc[3];
  return out;
}

double CfdCase::plane_at(const std::vector<float>& values, double x_m, double y_m, size_t lo,
                         double t) const {
  const double fx = (x_m - x0_m_) / dx_m_, fy = (std::abs(y_m) - y0_m_) / dy_m_;
  if (!(fx >= 0.0 && fy >= 0.0 && fx <= static_cast<double>(nx_ - 1) &&
        fy <= static_cast<double>(ny_ - 1))) {
    return 0.0;
  }
  const long ix = std::min(static_cast<long>(fx), nx_ - 2);
  const long iy = std::min(static_cast<long>(fy), ny_ - 2);
  const double tx = fx - static_cast<double>(ix), ty = fy - static_cast<double>(iy);
  auto plane = [&](size_t h) {
    const float* r0 =
        values.data() +
        (h * static_cast<size_t>(ny_) + static_cast<size_t>(iy)) * static_cast<size_t>(nx_) +
        static_cast<size_t>(ix);
    const float* r1 = r0 + nx_;
    return (1.0 - ty) * ((1.0 - tx) * r0[0] + tx * r0[1]) + ty * ((1.0 - tx) * r1[0] + tx * r1[1]);
  };
  return t > 0.0 ? (1.0 - t) * plane(lo) + t * plane(lo + 1) : plane(lo);
}

double CfdCase::vertical_at(double x_m, double y_m, double z_m) const {
  const auto [lo, t] = height_bracket(z_m);
  return plane_at(uz_, x_m, y_m, lo, t);
}

Eigen::Vector2d CfdCase::pressure_gradient_at(double x_m, double y_m, double z_m) const {
  const auto [lo, t] = height_bracket(z_m);
  return pressure_gradient_at(x_m, y_m, lo, t);
}

Eigen::Vector2d CfdCase::pressure_gradient_at(double x_m, double y_m, size_t lo, double t) const {
  // One pitch each side: the bilinear field's own slope jumps at every grid line.
  const double hx = dx_m_, hy = dy_m_;
  return {(plane_at(p_, x_m + hx, y_m, lo, t) - plane_at(p_, x_m - hx, y_m, lo, t)) / (2.0 * hx),
          (plane_at(p_, x_m, y_m + hy, lo, t) - plane_at(p_, x_m, y_m - hy, lo, t)) / (2.0 * hy)};
}

const char* CfdField::kFormationData =
    "the jet's start-up (startup_tilt00_d40.json) and pulse cases (pulse<MS>ms_tilt00_d40.json; "
    "docs/cfd.md)";

CfdField::CfdField(std::vector<CfdCase> cases, NozzleGeometry geometry,
                   std::optional<CfdStartup> startup, std::optional<WallJetFormation> formation)
    : cases_(std::move(cases)),
      geometry_(geometry),
      startup_(std::move(startup)),
      formation_(std::move(formation)) {
  if (cases_.empty()) throw InputError("CFD field: no case");
  std::sort(cases_.begin(), cases_.end(),
            [](const CfdCase& a, const CfdCase& b) { return a.tilt_rad() < b.tilt_rad(); });
  for (size_t i = 1; i < cases_.size(); ++i) {
    if (cases_[i].heights_m() != cases_[0].heights_m()) {
      throw InputError("CFD field: cases " + cases_[0].name() + " and " + cases_[i].name() +
                       " are sampled at different heights");
    }
    if (cases_[i].tilt_rad() == cases_[i - 1].tilt_rad()) {
      throw InputError("CFD field: cases " + cases_[i - 1].name() + " and " + cases_[i].name() +
                       " have the same tilt");
    }
  }
}

CfdField CfdField::read_dir(const std::string& dir, int mesh_level, double inlet_diameter_m) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir + ": not a folder of CFD cases");
  std::vector<std::string> headers;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() == ".json" && name.rfind("tilt", 0) == 0) {
      headers.push_back(entry.path().string());
    }
  }
  std::sort(headers.begin(), headers.end());
  std::vector<CfdCase> cases;
  for (const std::string& path : headers) {
    CfdCase c = CfdCase::read(path);
    if (c.held_out() || c.mesh_level() != mesh_level ||
        std::abs(c.inlet_diameter_m() - inlet_diameter_m) > 1e-9) {
      continue;
    }
    cases.push_back(std::move(c));
  }
  if (cases.empty()) {
    throw InputError(dir + ": no CFD case of mesh level " + std::to_string(mesh_level) +
                     " and inlet " + std::to_string(inlet_diameter_m) + " m (docs/cfd.md)");
  }
  const fs::path startup = fs::path(dir) / "startup_tilt00_d40.json";
  std::optional<CfdStartup> timings;
  if (fs::exists(startup, ec)) timings = CfdStartup::read(startup.string());
  std::optional<WallJetFormation> formation;
  const std::vector<CfdPulse> pulses = WallJetFormation::read_pulses(dir);
  if (!pulses.empty()) formation = WallJetFormation::fit(pulses);
  return CfdField(std::move(cases), NozzleGeometry{}, std::move(timings), std::move(formation));
}

CfdField::Bracket CfdField::bracket(double tilt_rad) const {
  const double lo_t = min_tilt_rad(), hi_t = max_tilt_rad();
  if (!(tilt_rad >= lo_t - 1e-12 && tilt_rad <= hi_t + 1e-12)) {
    throw InputError("CFD field: tilt " + std::to_string(rad_to_deg(tilt_rad)) +
                     " deg is outside the cases' [" + std::to_string(rad_to_deg(lo_t)) + ", " +
                     std::to_string(rad_to_deg(hi_t)) + "] deg");
  }
  Bracket b;
  if (cases_.size() == 1) return {0, 0, 0.0, cases_[0].stagnation_x_m()};
  while (b.lo + 2 < cases_.size() && cases_[b.lo + 1].tilt_rad() < tilt_rad) ++b.lo;
  b.hi = b.lo + 1;
  const CfdCase &a = cases_[b.lo], &c = cases_[b.hi];
  b.w = std::clamp((tilt_rad - a.tilt_rad()) / (c.tilt_rad() - a.tilt_rad()), 0.0, 1.0);
  // s linear in |c| = h tan(tilt) between the two cases.
  const double ca = std::tan(a.tilt_rad()), cc = std::tan(c.tilt_rad()),
               ct = std::tan(std::clamp(tilt_rad, a.tilt_rad(), c.tilt_rad()));
  const double ws = (ct - ca) / (cc - ca);
  b.s_x = (1.0 - ws) * a.stagnation_x_m() + ws * c.stagnation_x_m();
  return b;
}

CfdOrientedField CfdField::at(const NozzleOrientation& o) const {
  const Bracket b = bracket(o.tilt_rad);
  CfdOrientedField f;
  f.field_ = this;
  f.orientation_ = o;
  f.lo_ = b.lo;
  f.hi_ = b.hi;
  f.w_ = b.hi != b.lo ? b.w : 0.0;
  f.shift_lo_ = cases_[b.lo].stagnation_x_m() - b.s_x;
  f.shift_hi_ = cases_[b.hi].stagnation_x_m() - b.s_x;
  f.cos_pan_ = std::cos(o.pan_rad);
  f.sin_pan_ = std::sin(o.pan_rad);
  f.s_W_ = b.s_x * Eigen::Vector2d(f.cos_pan_, f.sin_pan_);
  f.pressure_radius_m_ =
      std::max(cases_[b.lo].pressure_radius_m(), cases_[b.hi].pressure_radius_m());
  return f;
}

Eigen::Vector2d CfdField::stagnation_point(const NozzleOrientation& o) const {
  return at(o).stagnation_point();
}

CfdSample CfdField::at(const NozzleOrientation& o, const Eigen::Vector2d& p_W, double z_m) const {
  return at(o).at(p_W, z_m);
}

CfdSample CfdOrientedField::at(const Eigen::Vector2d& p_W, double z_m) const {
  const double c = cos_pan_, s = sin_pan_;
  // The point in the case frame (pan 0); each case shifted to put its s on the interpolated s.
  // Every case has the same heights (CfdField checks), so one height bracket serves both.
  const double x = c * p_W.x() + s * p_W.y(), y = -s * p_W.x() + c * p_W.y();
  const double y_abs = std::abs(y);
  const CfdCase& lo = field_->cases_[lo_];
  const auto [h, t] = lo.height_bracket(z_m);
  double acc[4] = {0.0, 0.0, 0.0, 0.0};
  lo.accumulate(x + shift_lo_, y_abs, h, t, 1.0 - w_, acc);
  if (w_ > 0.0) field_->cases_[hi_].accumulate(x + shift_hi_, y_abs, h, t, w_, acc);
  const double ux = acc[0], uy = y < 0.0 ? -acc[1] : acc[1];
  // Back to the world frame.
  CfdSample out;
  out.u_W = Eigen::Vector2d(c * ux - s * uy, s * ux + c * uy);
  out.k = acc[2];
  out.epsilon = acc[3];
  return out;
}

double CfdOrientedField::vertical_at(const Eigen::Vector2d& p_W, double z_m) const {
  const double x = cos_pan_ * p_W.x() + sin_pan_ * p_W.y();
  const double y = -sin_pan_ * p_W.x() + cos_pan_ * p_W.y();
  const double lo = field_->cases_[lo_].vertical_at(x + shift_lo_, y, z_m);
  if (!(w_ > 0.0)) return lo;
  return (1.0 - w_) * lo + w_ * field_->cases_[hi_].vertical_at(x + shift_hi_, y, z_m);
}

Eigen::Vector2d CfdOrientedField::pressure_gradient_at(const Eigen::Vector2d& p_W,
                                                       double z_m) const {
  const double c = cos_pan_, s = sin_pan_;
  const double x = c * p_W.x() + s * p_W.y(), y = -s * p_W.x() + c * p_W.y();
  // Every case has the same heights, so one height bracket serves both (as in at()).
  const CfdCase& lo = field_->cases_[lo_];
  const auto [h, t] = lo.height_bracket(z_m);
  Eigen::Vector2d g = lo.pressure_gradient_at(x + shift_lo_, y, h, t);
  if (w_ > 0.0) {
    g = (1.0 - w_) * g + w_ * field_->cases_[hi_].pressure_gradient_at(x + shift_hi_, y, h, t);
  }
  return {c * g.x() - s * g.y(), s * g.x() + c * g.y()};
}

}  // namespace airtwin
