#include "models/wall_jet_formation.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <utility>

#include "common/errors.h"
#include "models/json_file.h"

namespace airtwin {
namespace {

using Json = nlohmann::json;
namespace fs = std::filesystem;

// Sum of squared misfits of 1 - exp(-T / tau) at one distance.
double misfit(double tau_s, const std::vector<std::pair<double, double>>& pulses) {
  double sum = 0.0;
  for (const auto& [t, f] : pulses) {
    const double e = 1.0 - std::exp(-t / tau_s) - f;
    sum += e * e;
  }
  return sum;
}

// The least-squares tau (s) by golden-section search in log tau over [0.01, 10] s: the misfit
// of a first-order rise is unimodal in tau for fractions in (0, 1].
double fit_tau(const std::vector<std::pair<double, double>>& pulses) {
  const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = std::log(0.01), b = std::log(10.0);
  double c = b - phi * (b - a), d = a + phi * (b - a);
  double fc = misfit(std::exp(c), pulses), fd = misfit(std::exp(d), pulses);
  for (int i = 0; i < 80; ++i) {
    if (fc < fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - phi * (b - a);
      fc = misfit(std::exp(c), pulses);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + phi * (b - a);
      fd = misfit(std::exp(d), pulses);
    }
  }
  return std::exp(0.5 * (a + b));
}

}  // namespace

CfdPulse CfdPulse::read(const std::string& path) {
  const Json j = read_json_file(path);
  CfdPulse p;
  p.pulse_s = json_number(j, "pulse_s", path);
  p.valve_s = json_number(j, "valve_opening_s", path);
  const double end_s = json_number(j, "end_time_s", path);
  const double probe_s = json_number(j, "probe_interval_s", path);
  if (!(p.pulse_s > p.valve_s && p.valve_s >= 0.0 && end_s > p.pulse_s && probe_s > 0.0)) {
    throw InputError(path +
                     ": expected 0 <= valve_opening_s < pulse_s < end_time_s and "
                     "probe_interval_s > 0");
  }
  if (!j.contains("figures") || !j.at("figures").is_object() ||
      !j.at("figures").contains("floor") || !j.at("figures").at("floor").is_array()) {
    throw InputError(path + ": missing field 'figures.floor'");
  }
  const Json& floor = j.at("figures").at("floor");
  double z_floor = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < floor.size(); ++i) {
    const std::string where = path + ": figures.floor[" + std::to_string(i) + "]";
    z_floor = std::min(z_floor, json_number(floor[i], "height_m", where));
  }
  // (r, peak fraction, peak time) at the lowest height, outward.
  struct Probe {
    double r, fraction, t;
  };
  std::vector<Probe> probes;
  for (size_t i = 0; i < floor.size(); ++i) {
    const Json& e = floor[i];
    const std::string where = path + ": figures.floor[" + std::to_string(i) + "]";
    if (json_number(e, "height_m", where) != z_floor) continue;
    const double r = json_number(e, "r_m", where);
    // No fraction where the steady air is too weak to divide by (at s).
    if (!e.contains("peak_fraction") || e.at("peak_fraction").is_null()) continue;
    probes.push_back(
        {r, json_number(e, "peak_fraction", where), json_number(e, "peak_t_s", where)});
  }
  std::sort(probes.begin(), probes.end(), [](const Probe& a, const Probe& b) { return a.r < b.r; });
  for (const Probe& q : probes) {
    if (q.t >= end_s - probe_s - 1e-9) break;  // still arriving when the run ended
    if (!(q.r > 0.0 && q.fraction > 0.0)) {
      throw InputError(path + ": a floor probe at r = " + std::to_string(q.r) +
                       " m has peak_fraction " + std::to_string(q.fraction) +
                       "; expected r > 0 and a fraction > 0");
    }
    p.r_m.push_back(q.r);
    p.peak_fraction.push_back(q.fraction);
  }
  if (p.r_m.empty()) {
    throw InputError(path + ": no floor probe whose peak came before the run's end");
  }
  return p;
}

std::vector<CfdPulse> WallJetFormation::read_pulses(const std::string& dir) {
  std::vector<std::string> paths;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    const std::string tail = "ms_tilt00_d40.json";
    if (name.rfind("pulse", 0) == 0 && name.size() > 5 + tail.size() &&
        name.compare(name.size() - tail.size(), tail.size(), tail) == 0) {
      paths.push_back(entry.path().string());
    }
  }
  std::sort(paths.begin(), paths.end());
  std::vector<CfdPulse> pulses;
  for (const std::string& p : paths) pulses.push_back(CfdPulse::read(p));
  return pulses;
}

WallJetFormation WallJetFormation::fit(const std::vector<CfdPulse>& pulses) {
  if (pulses.empty()) throw InputError("wall jet formation: no pulse to fit");
  // Each distance's pulses as (effective length, fraction capped at the steady air's 1).
  std::map<double, std::vector<std::pair<double, double>>> by_r;
  for (const CfdPulse& p : pulses) {
    for (size_t i = 0; i < p.r_m.size(); ++i) {
      by_r[p.r_m[i]].emplace_back(p.effective_s(), std::min(1.0, p.peak_fraction[i]));
    }
  }
  std::vector<double> r, tau;
  for (const auto& [ri, at_r] : by_r) {
    r.push_back(ri);
    tau.push_back(fit_tau(at_r));
  }
  return WallJetFormation(std::move(r), std::move(tau));
}

WallJetFormation::WallJetFormation(std::vector<double> r_m, std::vector<double> tau_s)
    : r_m_(std::move(r_m)), tau_s_(std::move(tau_s)) {
  if (r_m_.empty() || r_m_.size() != tau_s_.size()) {
    throw InputError("wall jet formation: expected at least one distance with one time each");
  }
  for (size_t i = 0; i < r_m_.size(); ++i) {
    if (!(std::isfinite(r_m_[i]) && r_m_[i] > 0.0 && (i == 0 || r_m_[i] > r_m_[i - 1]))) {
      throw InputError("wall jet formation: distances must be positive and increasing, got " +
                       std::to_string(r_m_[i]) + " m at entry " + std::to_string(i));
    }
    if (!(std::isfinite(tau_s_[i]) && tau_s_[i] > 0.0)) {
      throw InputError("wall jet formation: the time at r = " + std::to_string(r_m_[i]) +
                       " m must be finite and > 0 s, got " + std::to_string(tau_s_[i]));
    }
  }
}

double WallJetFormation::time_s(double r_m) const {
  if (!(r_m > r_m_.front())) return tau_s_.front();
  if (r_m >= r_m_.back()) return tau_s_.back();
  const size_t hi =
      static_cast<size_t>(std::upper_bound(r_m_.begin(), r_m_.end(), r_m) - r_m_.begin());
  const size_t lo = hi - 1;
  const double w = (r_m - r_m_[lo]) / (r_m_[hi] - r_m_[lo]);
  return tau_s_[lo] + w * (tau_s_[hi] - tau_s_[lo]);
}

double WallJetFormation::pulse_peak_fraction(double pulse_s, double r_m) const {
  return 1.0 - std::exp(-std::max(0.0, pulse_s) / time_s(r_m));
}

}  // namespace airtwin
