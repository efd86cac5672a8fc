#include "models/cfd_startup.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <utility>

#include "common/errors.h"
#include "models/json_file.h"

namespace airtwin {
namespace {

using Json = nlohmann::json;

}  // namespace

CfdStartup::CfdStartup(double transit_s, std::vector<double> r_m, std::vector<double> arrival_s)
    : transit_s_(transit_s), r_m_(std::move(r_m)), arrival_s_(std::move(arrival_s)) {
  if (!(std::isfinite(transit_s_) && transit_s_ >= 0.0)) {
    throw InputError("CFD start-up: transit must be a finite time >= 0 s, got " +
                     std::to_string(transit_s_));
  }
  if (r_m_.size() != arrival_s_.size() || r_m_.size() < 2) {
    throw InputError("CFD start-up: expected at least two floor arrivals with one distance each");
  }
  for (size_t i = 0; i < r_m_.size(); ++i) {
    if (!(std::isfinite(r_m_[i]) && r_m_[i] > 0.0 && (i == 0 || r_m_[i] > r_m_[i - 1]))) {
      throw InputError("CFD start-up: floor distances must be positive and increasing, got " +
                       std::to_string(r_m_[i]) + " m at entry " + std::to_string(i));
    }
    if (!(std::isfinite(arrival_s_[i]) && arrival_s_[i] >= transit_s_)) {
      throw InputError("CFD start-up: the arrival at r = " + std::to_string(r_m_[i]) +
                       " m must be a finite time at or after the transit " +
                       std::to_string(transit_s_) + " s, got " + std::to_string(arrival_s_[i]));
    }
  }
}

CfdStartup CfdStartup::read(const std::string& path) {
  const Json j = read_json_file(path);
  if (!j.is_object() || !j.contains("figures") || !j.at("figures").is_object()) {
    throw InputError(path + ": missing field 'figures'");
  }
  const Json& figures = j.at("figures");
  for (const char* key : {"axis", "floor"}) {
    if (!figures.contains(key) || !figures.at(key).is_array() || figures.at(key).empty()) {
      throw InputError(path + ": figures." + key + ": expected a non-empty list");
    }
  }
  // The free jet's head: the axis probe nearest the floor that has an arrival.
  double transit = std::numeric_limits<double>::quiet_NaN();
  double lowest_z = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < figures.at("axis").size(); ++i) {
    const Json& e = figures.at("axis")[i];
    const std::string where = path + ": figures.axis[" + std::to_string(i) + "]";
    const double z = json_number(e, "z_m", where);
    if (!e.contains("arrival_s") || e.at("arrival_s").is_null()) continue;
    const double t = json_number(e, "arrival_s", where);
    if (z < lowest_z) {
      lowest_z = z;
      transit = t;
    }
  }
  if (!std::isfinite(transit)) throw InputError(path + ": figures.axis: no arrival_s on the axis");
  // The wall jet's arrival at the lowest floor height, where the air was strong enough to time.
  double z_floor = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < figures.at("floor").size(); ++i) {
    const std::string where = path + ": figures.floor[" + std::to_string(i) + "]";
    z_floor = std::min(z_floor, json_number(figures.at("floor")[i], "height_m", where));
  }
  std::vector<std::pair<double, double>> arrivals;
  for (size_t i = 0; i < figures.at("floor").size(); ++i) {
    const Json& e = figures.at("floor")[i];
    const std::string where = path + ": figures.floor[" + std::to_string(i) + "]";
    if (json_number(e, "height_m", where) != z_floor) continue;
    if (!e.contains("arrival_s") || e.at("arrival_s").is_null()) continue;
    arrivals.emplace_back(json_number(e, "r_m", where), json_number(e, "arrival_s", where));
  }
  std::sort(arrivals.begin(), arrivals.end());
  std::vector<double> r, t;
  for (const auto& [ri, ti] : arrivals) {
    r.push_back(ri);
    t.push_back(ti);
  }
  try {
    return CfdStartup(transit, std::move(r), std::move(t));
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

double CfdStartup::wall_jet_lag_s(double r_m) const {
  const auto lag = [&](size_t i) { return arrival_s_[i] - transit_s_; };
  if (!(r_m > 0.0)) return 0.0;
  if (r_m <= r_m_.front()) return lag(0) * r_m / r_m_.front();
  const size_t n = r_m_.size();
  size_t hi = static_cast<size_t>(std::upper_bound(r_m_.begin(), r_m_.end(), r_m) - r_m_.begin());
  hi = std::min(hi, n - 1);
  const size_t lo = hi - 1;
  const double w = (r_m - r_m_[lo]) / (r_m_[hi] - r_m_[lo]);
  return std::max(0.0, lag(lo) + w * (lag(hi) - lag(lo)));
}

}  // namespace airtwin
