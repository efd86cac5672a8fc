// airtwin maketable: construct a coefficient table from wall-jet physics (models/wall_jet_table.h).
// The shipped constructed table is exactly `airtwin maketable --out
// models/data/constructed_field_table.csv` (the default field model is the one fitted to the CFD).

#include <cstdio>

#include "app/cli_common.h"
#include "app/commands.h"
#include "common/csv.h"
#include "common/errors.h"
#include "models/wall_jet_table.h"

namespace airtwin::cli {
namespace {

struct MakeTableArgs {
  WallJetDesign design;
  std::string tilts = "0,22.5,45";
  std::string out;
};

std::vector<double> parse_list(const std::string& text, const std::string& flag) {
  std::vector<double> out;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    const std::string item =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const std::optional<double> v = parse_finite_double(item);
    if (!v) throw UsageError(flag + ": expected comma-separated numbers, got '" + text + "'");
    out.push_back(*v);
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

void run_maketable(MakeTableArgs a) {
  a.design.tilts_deg = parse_list(a.tilts, "--tilts");
  const FieldTable table = construct_wall_jet_table(a.design);
  write_text_file(a.out, table.to_csv());
  std::printf("maketable: %zu tilts x %d directions -> %s\n", table.n_tilts(),
              FieldTable::kAlphaBins, a.out.c_str());
}

}  // namespace

void add_maketable_command(CLI::App& app) {
  auto args = std::make_shared<MakeTableArgs>();
  CLI::App* sub = app.add_subcommand(
      "maketable",
      "Construct an eq. (3) coefficient table from wall-jet physics and the paper's\n"
      "numbers (docs/field_model.md). The defaults reproduce the shipped table.");
  WallJetDesign& d = args->design;
  sub->add_option("--tilts", args->tilts, "Tilts of the table, degrees")->capture_default_str();
  sub->add_option("--peak-speed", d.peak_speed_mps, "Largest peak air speed, m/s")
      ->capture_default_str();
  sub->add_option("--peak-radius", d.peak_radius_m, "Peak radius of the normal jet, m")
      ->capture_default_str();
  sub->add_option("--reach-radius", d.reach_radius_m,
                  "Radius where the normal jet has reach-speed, m")
      ->capture_default_str();
  sub->add_option("--reach-speed", d.reach_speed_mps, "Normal jet's speed at reach-radius, m/s")
      ->capture_default_str();
  sub->add_option("--spread-exponent", d.spread_exponent,
                  "Speed ~ (oblique momentum share)^exponent; 0.5 is the inviscid sheet")
      ->capture_default_str();
  sub->add_option("--out", args->out, "Output table CSV")->required();
  sub->callback([args] { run_maketable(*args); });
}

}  // namespace airtwin::cli
