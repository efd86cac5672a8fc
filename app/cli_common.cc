#include "app/cli_common.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/csv.h"
#include "common/errors.h"
#include "common/units.h"

namespace airtwin::cli {

Eigen::Vector2d parse_xy(const std::string& text, const std::string& flag) {
  const size_t comma = text.find(',');
  std::optional<double> x, y;
  if (comma != std::string::npos) {
    x = parse_finite_double(text.substr(0, comma));
    y = parse_finite_double(text.substr(comma + 1));
  }
  if (!x || !y) {
    throw UsageError(flag + ": expected two finite numbers 'X,Y' in metres, got '" + text + "'");
  }
  return {*x, *y};
}

void require_range(double v, double lo, double hi, const std::string& flag,
                   const std::string& what) {
  if (!std::isfinite(v) || v < lo || v > hi) {
    throw UsageError(flag + ": expected " + what + ", got " + std::to_string(v));
  }
}

void ensure_parent_dir(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (parent.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(parent, ec);
  if (ec)
    throw InputError(path + ": cannot create directory '" + parent.string() + "': " + ec.message());
}

void write_text_file(const std::string& path, const std::string& text) {
  ensure_parent_dir(path);
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError(path + ": cannot open file for writing");
  out << text;
  out.close();
  if (!out) throw InputError(path + ": write failed");
}

std::vector<double> parse_degree_list(const std::string& text, const std::string& flag) {
  std::vector<double> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    const auto v = parse_finite_double(item);
    if (!v) throw UsageError(flag + ": expected comma-separated degrees, got '" + item + "'");
    out.push_back(deg_to_rad(*v));
  }
  if (out.empty()) throw UsageError(flag + ": give at least one value");
  return out;
}

NoiseLevel parse_noise(const std::string& level) {
  if (level == "none") return {0.0, 0.0};
  if (level == "low") return {3.0, 0.7};
  if (level == "high") return {6.0, 1.0};
  throw UsageError("--noise: expected none, low or high, got '" + level + "'");
}

std::vector<Effect> apply_effect_flags(const std::vector<std::string>& texts,
                                       TwinParameters* twin) {
  try {
    std::vector<Effect> effects;
    for (const std::string& text : texts) effects.push_back(parse_effect(text));
    apply_effects(effects, twin);
    return effects;
  } catch (const InputError& e) {
    throw UsageError(std::string("--effect: ") + e.what());
  }
}

}  // namespace airtwin::cli
