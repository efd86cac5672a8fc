// airtwin hotwire: the paper's Appendix A hot-wire campaign simulated from the jet's CFD
// (models/hotwire.h): one-minute mean readings of an omnidirectional thermal anemometer on an
// 11 x 11 grid over the 2 x 2 m workspace, 1.5 cm above the floor, per tilt. Writes the measured
// grid that `airtwin fitfield --grid` reads and prints a JSON summary.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "app/cfd_source.h"
#include "app/cli_common.h"
#include "app/commands.h"
#include "common/errors.h"
#include "common/units.h"
#include "models/field_grid.h"
#include "models/hotwire.h"

namespace airtwin::cli {
namespace {

struct HotWireArgs {
  std::string tilts;
  double pan_deg = 0.0;
  uint64_t seed = 1;
  std::string cfd = AIRTWIN_CFD_DIR;
  int points = 11;
  double side_m = 2.0;
  double height_m = 0.015;
  int threads = 0;
  std::string out;
  HotWireSpec spec;
};

// The library's fields and the flags that set them.
constexpr std::initializer_list<FlagOf> kHotWireFlags = {
    {"hotwire.tilts", "--tilts"},
    {"hotwire.pan_rad", "--pan"},
    {"hotwire.points", "--points"},
    {"hotwire.side_m", "--side"},
    {"hotwire.height_m", "--height"},
    {"hotwire.threads", "--threads"},
    {"hotwire.detection_limit_mps", "--detection-limit"},
    {"hotwire.accuracy_fraction", "--accuracy"},
    {"hotwire.time_constant_s", "--time-constant"},
    {"hotwire.sample_rate_hz", "--rate"},
    {"hotwire.averaging_time_s", "--average"},
    {"hotwire.min_step_s", "--min-step"}};

double rounded(double v, int decimals) {
  const double scale = std::pow(10.0, decimals);
  return std::round(v * scale) / scale;
}

// Per tilt: the mean reading against the CFD's mean air, and how far the readings sit above the
// horizontal speed eq. (3) models.
nlohmann::ordered_json summary_json(const HotWireArgs& a, const HotWireCampaign& campaign,
                                    const HotWireResult& r) {
  using json = nlohmann::ordered_json;
  const HotWireSpec& s = a.spec;
  const size_t n = campaign.points_W.size();
  json tilts = json::array(), reading = json::array(), horizontal = json::array(),
       speed_3d = json::array(), over = json::array(), n_over = json::array();
  for (size_t t = 0; t < campaign.tilts_rad.size(); ++t) {
    double sum_r = 0, sum_h = 0, sum_3 = 0, sum_over = 0;
    size_t count_over = 0;
    for (size_t i = t * n; i < (t + 1) * n; ++i) {
      const double v = r.grid.samples[i].speed_mps, h = r.cfd_horizontal_speed_mps[i];
      sum_r += v;
      sum_h += h;
      sum_3 += r.cfd_speed_3d_mps[i];
      if (h >= s.detection_limit_mps && h > 0) {
        sum_over += (v - h) / h;
        ++count_over;
      }
    }
    tilts.push_back(rounded(rad_to_deg(campaign.tilts_rad[t]), 6));
    reading.push_back(rounded(sum_r / n, 5));
    horizontal.push_back(rounded(sum_h / n, 5));
    speed_3d.push_back(rounded(sum_3 / n, 5));
    over.push_back(count_over > 0 ? json(rounded(100.0 * sum_over / count_over, 3)) : json());
    n_over.push_back(count_over);
  }
  return {
      {"command", "hotwire"},
      {"cfd", a.cfd},
      {"out", a.out},
      {"seed", a.seed},
      {"pan_deg", a.pan_deg},
      {"tilts_deg", tilts},
      {"points", {{"per_side", a.points}, {"side_m", a.side_m}, {"height_m", a.height_m}}},
      {"instrument",
       {{"model", "omnidirectional thermal anemometer (degreeC UAS150), reads |(ux, uy, uz)|"},
        {"detection_limit_mps", s.detection_limit_mps},
        {"static_law", "v for v >= 2 U0, U0 + v^2 / (4 U0) below (free-convection floor)"},
        {"accuracy_fraction", s.accuracy_fraction},
        {"time_constant_s", s.time_constant_s},
        {"sample_rate_hz", s.sample_rate_hz},
        {"averaging_time_s", s.averaging_time_s}}},
      {"calibration_gain", rounded(r.gain, 6)},
      {"mean_reading_mps", reading},
      {"mean_cfd_horizontal_speed_mps", horizontal},
      {"mean_cfd_speed_3d_mps", speed_3d},
      {"mean_overreading_pct", over},
      {"n_overreading_points", n_over},
      {"overreading_definition",
       "mean of (reading - |(ux, uy)|) / |(ux, uy)| * 100 over points where the CFD's horizontal "
       "speed is at least the detection limit"},
  };
}

void run_hotwire(HotWireArgs a) {
  // The campaign and the instrument, in SI; the library names its fields, mapped to our flags.
  HotWireCampaign campaign;
  campaign.tilts_rad = parse_degree_list(a.tilts, "--tilts");
  campaign.pan_rad = deg_to_rad(a.pan_deg);
  campaign.seed = a.seed;
  campaign.height_m = a.height_m;
  require_range(a.threads, 0, 256, "--threads", "a thread count in [0, 256] (0: all cores)");
  campaign.threads = a.threads > 0
                         ? a.threads
                         : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  with_flags(kHotWireFlags, [&] {
    campaign.points_W = HotWireCampaign::square_grid(a.side_m, a.points);
    campaign.validate();
    a.spec.validate();
  });

  const CfdField cfd = read_cfd_source(a.cfd);
  ensure_parent_dir(a.out);
  const HotWireResult result = with_flags(
      kHotWireFlags, [&] { return simulate_hotwire_campaign(cfd, campaign, a.spec, a.out); });
  write_text_file(a.out, field_grid_to_csv(result.grid));

  // One top-level key per line, each value compact.
  const nlohmann::ordered_json report = summary_json(a, campaign, result);
  std::string text = "{\n";
  for (auto it = report.begin(); it != report.end(); ++it) {
    text += "  " + nlohmann::json(it.key()).dump() + ": " + it.value().dump();
    text += std::next(it) == report.end() ? "\n" : ",\n";
  }
  std::printf("%s}\n", text.c_str());
}

}  // namespace

void add_hotwire_command(CLI::App& app) {
  auto args = std::make_shared<HotWireArgs>();
  CLI::App* sub = app.add_subcommand(
      "hotwire",
      "Simulate the Appendix A hot-wire campaign from the jet's CFD: the one-minute mean reading\n"
      "of an omnidirectional thermal anemometer (degreeC UAS150: |3-D velocity| with turbulence,\n"
      "a free-convection floor near its ~0.1 m/s detection limit, a first-order response, a\n"
      "calibration gain) on an N x N grid 1.5 cm above the floor, per tilt. Writes the measured\n"
      "grid CSV pan_deg,tilt_deg,x,y,speed for 'airtwin fitfield --grid' and prints a JSON\n"
      "summary. Deterministic for a seed. Model and sources: docs/cfd.md.");
  sub->add_option("--tilts", args->tilts, "Tilts to measure, degrees, comma-separated (0,22.5,45)")
      ->required();
  sub->add_option("--pan", args->pan_deg, "Pan of every measurement, degrees")
      ->capture_default_str();
  sub->add_option("--seed", args->seed, "Seed of the turbulence and the calibration gain")
      ->capture_default_str();
  sub->add_option("--cfd", args->cfd,
                  "CFD: a folder of cases (interpolated between tilts) or one case's .json "
                  "header (that tilt only, e.g. the held-out 37.5 deg)")
      ->capture_default_str();
  sub->add_option("--points", args->points, "Points per side of the square grid")
      ->capture_default_str();
  sub->add_option("--side", args->side_m, "Side of the square grid centred on the origin (m)")
      ->capture_default_str();
  sub->add_option("--height", args->height_m, "Sensor height above the floor (m)")
      ->capture_default_str();
  HotWireSpec& s = args->spec;
  sub->add_option("--detection-limit", s.detection_limit_mps,
                  "U0 (m/s): the reading in still air; exact from 2 U0 up")
      ->capture_default_str();
  sub->add_option("--accuracy", s.accuracy_fraction,
                  "Calibration accuracy, fraction of reading (2 sigma of one gain per campaign)")
      ->capture_default_str();
  sub->add_option("--time-constant", s.time_constant_s, "First-order response time constant (s)")
      ->capture_default_str();
  sub->add_option("--rate", s.sample_rate_hz, "Samples per second (Hz)")->capture_default_str();
  sub->add_option("--average", s.averaging_time_s, "Averaging time per point (s)")
      ->capture_default_str();
  sub->add_option("--min-step", s.min_step_s, "Finest simulation time step (s)")
      ->capture_default_str();
  sub->add_option("--threads", args->threads, "Points simulated in parallel (0: one per core)")
      ->capture_default_str();
  sub->add_option("--out", args->out, "Output measured-grid CSV")->required();
  sub->callback([args] { run_hotwire(*args); });
}

}  // namespace airtwin::cli
