// airtwin discrepancy: what the model gets wrong in measured trajectories, the physical cause,
// the extended model, and what it gains (models/discrepancy.h, docs/discrepancy.md).

#include <cstdio>
#include <filesystem>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "app/cli_common.h"
#include "app/commands.h"
#include "common/errors.h"
#include "models/air_field.h"
#include "models/discrepancy.h"
#include "models/extended_model.h"
#include "models/field_model_file.h"
#include "models/identified_model.h"
#include "models/trajectory_data.h"
#include "plots/residual_plot.h"

namespace airtwin::cli {
namespace {

struct DiscrepancyArgs {
  std::vector<std::string> data;
  std::vector<std::string> models;
  std::string table;
  double holdout = 0.3;
  uint64_t seed = 1;
  double window_s = 3.0;
  std::string prior_command;
  std::string out;
  bool quiet = false;
};

void run(const DiscrepancyArgs& a) {
  DiscrepancyOptions options;
  options.holdout_fraction = a.holdout;
  options.seed = a.seed;
  options.window_s = a.window_s;
  if (!a.prior_command.empty()) {
    const std::vector<double> v = parse_degree_list(a.prior_command, "--prior-command");
    if (v.size() != 2) {
      throw UsageError("--prior-command: expected PAN,TILT in degrees, got '" + a.prior_command +
                       "'");
    }
    options.prior_command = NozzleOrientation{v[0], v[1]};
  }
  // flags first, before any file is read or written
  with_flags({{"discrepancy.holdout_fraction", "--holdout"},
              {"discrepancy.window_s", "--window"},
              {"discrepancy.prior_command", "--prior-command"}},
             [&] { options.validate(); });

  // NAME=FILE: FILE's trajectories make experiment NAME; the others the unnamed one.
  std::vector<std::string> paths, experiment_of_file;
  bool any_experiment = false;
  for (const std::string& d : a.data) {
    static const std::regex kNamed("([A-Za-z][A-Za-z0-9_-]*)=(.+)");
    std::smatch m;
    if (std::regex_match(d, m, kNamed)) {
      experiment_of_file.push_back(m[1]);
      paths.push_back(m[2]);
      any_experiment = true;
    } else {
      experiment_of_file.emplace_back();
      paths.push_back(d);
    }
  }
  const TrajectoryFiles files = read_trajectory_files(paths);
  if (any_experiment && paths.size() > 1) {
    for (const Trajectory& t : files.set.trajectories) {  // ids are FILE_INDEX:ID, 1-based
      const size_t file = std::stoul(t.id.substr(0, t.id.find(':'))) - 1;
      if (!experiment_of_file[file].empty()) {
        options.experiment_of[t.id] = experiment_of_file[file];
      }
    }
  }
  const TrajectorySet& set = files.set;
  const std::string& source = files.source;
  const AirFieldModel field = field_model_or_default(a.table);
  // The nominal dynamics: the paper's, replaced per object type by the models given.
  std::map<std::string, ObjectDynamics> objects = {{"tracer", kTracerDynamics},
                                                   {"cotton", kCottonDynamics}};
  for (const std::string& path : a.models) {
    const IdentifiedModel model = read_identified_model(path);
    if (model.object.empty()) {
      throw InputError(path + ": the model names no object type (identify it with --object)");
    }
    objects[model.object] = model.eq8();
  }
  if (!a.quiet) {
    options.progress = [](const std::string& line) {
      std::fprintf(stderr, "discrepancy: %s\n", line.c_str());
    };
  }
  DiscrepancyReport report = analyse_discrepancy(set, field, objects, options);
  report.source = source;

  ExtendedModel extended;
  extended.objects = objects;
  extended.nozzle = options.nozzle;
  extended.extensions = report.extensions;
  extended.table = a.table;
  extended.source = source;
  std::filesystem::create_directories(a.out);
  write_text_file(a.out + "/report.json", discrepancy_report_json(report));
  write_text_file(a.out + "/report.md", discrepancy_report_markdown(report));
  write_text_file(a.out + "/extended_model.json", extended_model_json(extended));
  plots::write_residual_plots(report, a.out);
  if (report.chosen_correction >= 0) {
    write_text_file(a.out + "/correction.csv", discrepancy_correction_csv(report));
    plots::write_correction_plot(report, a.out + "/residual_correction.png");
  }

  std::string found;
  if (!report.decidable) {
    found = "undecided (see report.md)";
  } else if (report.found.empty()) {
    found = "none";
  }
  for (const std::string& f : report.found) {
    found += (found.empty() ? "" : ", ") + f;
    std::string rivals;
    for (const Rival& v : report.rivals) {
      if (v.cause == f) rivals += (rivals.empty() ? "" : " or ") + v.rival;
    }
    if (!rivals.empty()) found += " (the held-out data cannot tell it from " + rivals + ")";
  }
  std::printf("found: %s; held-out end MAPE %.1f %% -> %.1f %%%s; report in %s/report.md\n",
              found.c_str(), report.baseline_end_mape, report.extended_end_mape,
              report.unexplained ? "; unexplained structure left" : "", a.out.c_str());
}

}  // namespace

void add_discrepancy_command(CLI::App& app) {
  auto args = std::make_shared<DiscrepancyArgs>();
  CLI::App* sub = app.add_subcommand(
      "discrepancy",
      "Find what the model gets wrong in measured trajectories (Appendix D recordings or\n"
      "closed-loop logs): baseline errors and residual structure, a catalogue of physical causes\n"
      "fitted on a training split and tested on held-out data, and the extended model with the\n"
      "causes found, and whether what is left is still structured (a nonparametric correction).\n"
      "Writes report.json, report.md, extended_model.json, residual plots and, with a\n"
      "correction, correction.csv and residual_correction.png.\n"
      "docs/discrepancy.md.");
  sub->add_option("data", args->data,
                  "Trajectory CSV (traj,object,t,x,y,pan_deg,tilt_deg), or several (e.g. a\n"
                  "batch's logs): trajectory ids then become FILE_INDEX:ID, 1-based. NAME=FILE\n"
                  "puts a file's trajectories in experiment NAME (the others in an unnamed one):\n"
                  "a cause's held-out size may then be shown by one experiment's windows alone,\n"
                  "e.g. launched trials (collect --protocol launched) beside closed-loop logs")
      ->required();
  sub->add_option("--model", args->models,
                  "model.json from 'airtwin identify' (repeatable, one per object type); default:\n"
                  "the paper's coefficients");
  sub->add_option(
      "--table", args->table,
      std::string("The controller's air model: a coefficient table CSV or a field-model\n"
                  "JSON (eq. (2)'s a1, a2 and a table); ") +
          kDefaultFieldModelHelp);
  sub->add_option("--holdout", args->holdout, "Fraction of windows held out for scoring")
      ->capture_default_str();
  sub->add_option("--seed", args->seed, "Seed of the train / held-out split")
      ->capture_default_str();
  sub->add_option("--window", args->window_s,
                  "Longest prediction (s): longer trajectories are cut into windows")
      ->capture_default_str();
  sub->add_option(
      "--prior-command", args->prior_command,
      "PAN,TILT (deg): where the nozzle was before each trajectory's first sample, for\n"
      "Appendix D recordings without a lead-in (collect's idle is -90,50): the servos'\n"
      "travel from it is then predicted instead of left out");
  sub->add_option("--out", args->out, "Output folder")->required();
  sub->add_flag("--quiet", args->quiet, "No progress on stderr");
  sub->callback([args] { run(*args); });
}

}  // namespace airtwin::cli
