#include "models/hotwire.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <utility>

#include "common/errors.h"
#include "common/parallel_for.h"
#include "common/text.h"
#include "common/units.h"
#include "models/turbulence_time.h"

namespace airtwin {
namespace {

// Kolmogorov's constant of the Lagrangian structure function (Pope 2000, section 12.4).
constexpr double kC0 = 2.1;
// The settling time before the averaging window, in units of the slower of tau and T_E.
constexpr double kSettleTimes = 5.0;
// Per-point streams: index = (tilt in micro-degrees) << kPointBits | (point + 1); 0 is the gain.
constexpr int kPointBits = 20;

void require(bool ok, const char* field, const std::string& expected, double got) {
  if (!ok) throw FieldError(field, "must be " + expected + ", got " + format_short(got));
}

}  // namespace

void HotWireSpec::validate() const {
  require(
      std::isfinite(detection_limit_mps) && detection_limit_mps >= 0 && detection_limit_mps <= 10,
      "hotwire.detection_limit_mps", "in [0, 10] m/s", detection_limit_mps);
  require(std::isfinite(accuracy_fraction) && accuracy_fraction >= 0 && accuracy_fraction <= 0.2,
          "hotwire.accuracy_fraction", "in [0, 0.2]", accuracy_fraction);
  require(std::isfinite(time_constant_s) && time_constant_s >= 0 && time_constant_s <= 60,
          "hotwire.time_constant_s", "in [0, 60] s", time_constant_s);
  require(std::isfinite(sample_rate_hz) && sample_rate_hz >= 0.01 && sample_rate_hz <= 1e4,
          "hotwire.sample_rate_hz", "in [0.01, 10000] Hz", sample_rate_hz);
  require(std::isfinite(averaging_time_s) && averaging_time_s >= 1.0 / sample_rate_hz &&
              averaging_time_s <= 3600,
          "hotwire.averaging_time_s", "in [1 / sample_rate_hz, 3600] s", averaging_time_s);
  require(std::isfinite(min_step_s) && min_step_s >= 1e-6 && min_step_s <= 1.0 / sample_rate_hz,
          "hotwire.min_step_s", "in [1e-6, 1 / sample_rate_hz] s", min_step_s);
}

double hotwire_static_reading_mps(double speed_mps, const HotWireSpec& spec) {
  require(speed_mps >= 0, "hotwire.speed_mps", ">= 0 m/s", speed_mps);
  const double u0 = spec.detection_limit_mps;
  // Calibrated range: the speed itself; below 2 U0 the free-convection floor.
  if (speed_mps >= 2.0 * u0) return speed_mps;
  return u0 + speed_mps * speed_mps / (4.0 * u0);
}

double eulerian_integral_time_s(double mean_speed_mps, double k, double epsilon) {
  require(std::isfinite(k) && k > 0, "hotwire.k", "> 0 m^2/s^2", k);
  require(std::isfinite(epsilon) && epsilon > 0, "hotwire.epsilon", "> 0 m^2/s^3", epsilon);
  require(std::isfinite(mean_speed_mps) && mean_speed_mps >= 0, "hotwire.speed_mps", ">= 0 m/s",
          mean_speed_mps);
  // Decorrelation by the eddies' own life (T_L) and by the mean flow sweeping them past (L11 / U).
  const double t_lagrangian = 4.0 * k / (3.0 * kC0 * epsilon);
  return swept_integral_time_s(t_lagrangian, mean_speed_mps, k, epsilon);
}

double simulate_hotwire_mean_mps(const HotWireAir& air, const HotWireSpec& spec,
                                 RandomStream& rng) {
  spec.validate();
  if (!air.u_W.allFinite()) {
    throw FieldError("hotwire.u_W", "must be a finite velocity, got (" + format_short(air.u_W.x()) +
                                        ", " + format_short(air.u_W.y()) + ", " +
                                        format_short(air.u_W.z()) + ")");
  }
  require(std::isfinite(air.k) && air.k >= 0, "hotwire.k", ">= 0 m^2/s^2", air.k);
  const double speed = air.u_W.norm();
  if (air.k == 0.0) return hotwire_static_reading_mps(speed, spec);
  const double t_e = eulerian_integral_time_s(speed, air.k, air.epsilon);

  // Time steps: samples at the instrument's rate, each split into substeps that resolve the
  // faster of T_E and tau (at most 1 / min_step_s per second).
  const double tau = spec.time_constant_s;
  const double dt_sample = 1.0 / spec.sample_rate_hz;
  const double finest = std::max(0.25 * (tau > 0 ? std::min(t_e, tau) : t_e), spec.min_step_s);
  const long max_substeps =
      std::max(1L, static_cast<long>(std::floor(dt_sample / spec.min_step_s)));
  const long substeps =
      std::clamp(static_cast<long>(std::ceil(dt_sample / finest)), 1L, max_substeps);
  const double h = dt_sample / static_cast<double>(substeps);
  const long n_settle = static_cast<long>(std::ceil(kSettleTimes * std::max(tau, t_e) / dt_sample));
  const long n_samples = std::max(1L, std::lround(spec.averaging_time_s * spec.sample_rate_hz));

  // Exact Ornstein-Uhlenbeck update per component (variance sigma^2 = 2k/3 kept at any h), and
  // the exact first-order response to a reading held over the substep.
  const double sigma = std::sqrt(2.0 * air.k / 3.0);
  const double a = std::exp(-h / t_e);
  const double b = sigma * std::sqrt(-std::expm1(-2.0 * h / t_e));
  const double lag = tau > 0 ? -std::expm1(-h / tau) : 1.0;

  // Start in the stationary turbulence with the response at the first reading.
  Eigen::Vector3d u_turb(sigma * rng.normal(), sigma * rng.normal(), sigma * rng.normal());
  double response = hotwire_static_reading_mps((air.u_W + u_turb).norm(), spec);
  double sum = 0.0;
  for (long s = 0; s < n_settle + n_samples; ++s) {
    for (long j = 0; j < substeps; ++j) {
      for (int c = 0; c < 3; ++c) u_turb[c] = a * u_turb[c] + b * rng.normal();
      response += lag * (hotwire_static_reading_mps((air.u_W + u_turb).norm(), spec) - response);
    }
    // Average the samples of the window after settling.
    if (s >= n_settle) sum += response;
  }
  return sum / static_cast<double>(n_samples);
}

std::vector<Eigen::Vector2d> HotWireCampaign::square_grid(double side_m, int n) {
  require(std::isfinite(side_m) && side_m > 0 && side_m <= 2 * kMaxCoordinateM, "hotwire.side_m",
          "in (0, 200] m", side_m);
  require(n >= 2 && n <= 1000, "hotwire.points", "a count per side in [2, 1000]", n);
  std::vector<Eigen::Vector2d> points;
  points.reserve(static_cast<size_t>(n) * static_cast<size_t>(n));
  const double step = side_m / (n - 1);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i)
      points.emplace_back(-0.5 * side_m + i * step, -0.5 * side_m + j * step);
  }
  return points;
}

void HotWireCampaign::validate() const {
  if (tilts_rad.empty()) throw FieldError("hotwire.tilts", "must list at least one tilt");
  std::set<long long> seen;
  for (double t : tilts_rad) {
    require(std::isfinite(t) && t >= 0 && t < deg_to_rad(90.0), "hotwire.tilts",
            "tilts in [0, 90) deg", rad_to_deg(t));
    if (!seen.insert(std::llround(rad_to_deg(t) * 1e6)).second) {
      throw FieldError("hotwire.tilts", "lists tilt " + format_short(rad_to_deg(t)) + " deg twice");
    }
  }
  require(std::isfinite(pan_rad) && std::abs(pan_rad) <= 2 * kPi, "hotwire.pan_rad",
          "in [-2 pi, 2 pi] rad", pan_rad);
  if (points_W.empty()) throw FieldError("hotwire.points", "must hold at least one point");
  if (points_W.size() >= (size_t{1} << kPointBits)) {
    throw FieldError("hotwire.points",
                     "must hold fewer than 2^20 points, got " + std::to_string(points_W.size()));
  }
  for (size_t i = 0; i < points_W.size(); ++i) {
    const Eigen::Vector2d& p = points_W[i];
    if (!(p.allFinite() && p.cwiseAbs().maxCoeff() <= kMaxCoordinateM)) {
      throw FieldError("hotwire.points", "point " + std::to_string(i) + " (" + format_short(p.x()) +
                                             ", " + format_short(p.y()) +
                                             ") must be finite and within 100 m");
    }
  }
  require(std::isfinite(height_m) && height_m > 0 && height_m <= 0.1, "hotwire.height_m",
          "in (0, 0.1] m", height_m);
  require(threads >= 1, "hotwire.threads", ">= 1", threads);
}

HotWireResult simulate_hotwire_campaign(const CfdField& cfd, const HotWireCampaign& campaign,
                                        const HotWireSpec& spec, const std::string& source) {
  campaign.validate();
  spec.validate();

  // The nozzle orientations, resolved once (InputError for a tilt outside the CFD's range).
  std::vector<CfdOrientedField> fields;
  for (double tilt : campaign.tilts_rad) fields.push_back(cfd.at({campaign.pan_rad, tilt}));

  // One calibration gain for the campaign: the same probe measured every point.
  RandomStream gain_rng(campaign.seed, RandomPurpose::kMeasurement, 0);
  const double gain = 1.0 + 0.5 * spec.accuracy_fraction * gain_rng.normal();

  // Every (tilt, point) on its own stream, so no reading depends on the others or on the threads.
  const size_t n_points = campaign.points_W.size();
  std::vector<double> readings(fields.size() * n_points), horizontal(readings.size()),
      speed_3d(readings.size());
  parallel_for(readings.size(), campaign.threads, [&](size_t item) {
    const size_t t = item / n_points, i = item % n_points;
    const Eigen::Vector2d& p_W = campaign.points_W[i];
    const CfdSample mean = fields[t].at(p_W, campaign.height_m);
    HotWireAir air;
    air.u_W << mean.u_W, fields[t].vertical_at(p_W, campaign.height_m);
    air.k = std::max(mean.k, 0.0);
    air.epsilon = mean.epsilon;
    const auto tilt_key =
        static_cast<uint64_t>(std::llround(rad_to_deg(campaign.tilts_rad[t]) * 1e6));
    RandomStream rng(campaign.seed, RandomPurpose::kMeasurement,
                     (tilt_key << kPointBits) | static_cast<uint64_t>(i + 1));
    readings[item] = gain * simulate_hotwire_mean_mps(air, spec, rng);
    horizontal[item] = mean.u_W.norm();
    speed_3d[item] = air.u_W.norm();
  });

  // The measured grid, by tilt then point.
  HotWireResult result;
  result.gain = gain;
  result.grid.source = source;
  result.grid.kind = GridKind::kMeasured;
  result.grid.samples.reserve(readings.size());
  for (size_t t = 0; t < fields.size(); ++t) {
    for (size_t i = 0; i < n_points; ++i) {
      FieldSample s;
      s.orientation = {campaign.pan_rad, campaign.tilts_rad[t]};
      s.p_W = campaign.points_W[i];
      s.speed_mps = readings[t * n_points + i];
      result.grid.samples.push_back(s);
    }
  }
  result.cfd_horizontal_speed_mps = std::move(horizontal);
  result.cfd_speed_3d_mps = std::move(speed_3d);
  validate_field_grid(result.grid);
  return result;
}

}  // namespace airtwin
