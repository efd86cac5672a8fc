// airtwin probe: the twin's air at fixed floor points while the nozzle follows a program
// (sim/air_probe.h). Reads the program (t_s,pan_deg,tilt_deg) and the points (x_m,y_m[,z_m]),
// writes one CSV row per record and point: t_s,point,x_m,y_m,z_m,ux,uy.

#include <cstdio>
#include <memory>
#include <string>

#include "app/cli_common.h"
#include "app/commands.h"
#include "common/errors.h"
#include "common/text.h"
#include "models/cfd_field.h"
#include "sim/air_probe.h"

namespace airtwin::cli {
namespace {

struct ProbeArgs {
  std::string program;
  std::string points;
  std::string out;
  std::string cfd = AIRTWIN_CFD_DIR;
  bool formation = false;     // --air-formation: asked for (an error when the cases lack it)
  bool no_formation = false;  // --no-air-formation
  double formation_time_scale = AirTransportParameters{}.formation_time_scale;
  double front_co_flow = AirTransportParameters{}.front_co_flow;
  double front_counter_flow = AirTransportParameters{}.front_counter_flow;
  AirProbeSettings settings;
};

constexpr std::initializer_list<FlagOf> kProbeFlags = {
    {"air_probe.timestep_s", "--timestep"},
    {"air_probe.interval_s", "--interval"},
    {"air_probe.end_s", "--end"},
    {"air_transport.formation_time_scale", "--air-formation-time-scale"},
    {"air_transport.front_co_flow", "--air-front-co-flow"},
    {"air_transport.front_counter_flow", "--air-front-counter-flow"}};

void run_probe(const ProbeArgs& a) {
  AirTransportParameters transport;
  if (a.formation_time_scale != transport.formation_time_scale && a.no_formation) {
    throw UsageError("--air-formation-time-scale needs the formation (drop --no-air-formation)");
  }
  transport.formation = !a.no_formation;
  transport.formation_time_scale = a.formation_time_scale;
  transport.front_co_flow = a.front_co_flow;
  transport.front_counter_flow = a.front_counter_flow;
  with_flags(kProbeFlags, [&] {
    a.settings.validate();
    transport.validate();
  });
  const std::vector<ProgramKnot> program = read_nozzle_program(a.program);
  const std::vector<ProbePoint> points = read_probe_points(a.points);
  const CfdField cfd = CfdField::read_dir(a.cfd);
  if (a.formation && !cfd.forms_air()) {
    throw UsageError("--air-formation: " + a.cfd + " lacks " + CfdField::kFormationData);
  }
  const AirProbeRecord r = with_flags(
      kProbeFlags, [&] { return probe_air(cfd, transport, program, points, a.settings); });
  std::string csv = "t_s,point,x_m,y_m,z_m,ux,uy\n";
  char line[160];
  for (size_t k = 0; k < r.t_s.size(); ++k) {
    for (size_t i = 0; i < points.size(); ++i) {
      std::snprintf(line, sizeof line, "%.4f,%zu,%.4f,%.4f,%.4f,%.5f,%.5f\n", r.t_s[k], i,
                    points[i].p_W.x(), points[i].p_W.y(), points[i].z_m, r.u_W[k][i].x(),
                    r.u_W[k][i].y());
      csv += line;
    }
  }
  ensure_parent_dir(a.out);
  write_text_file(a.out, csv);
  std::printf("probe: %zu points x %zu records to %s s -> %s\n", points.size(), r.t_s.size(),
              format_number(r.t_s.back()).c_str(), a.out.c_str());
}

}  // namespace

void add_probe_command(CLI::App& app) {
  auto args = std::make_shared<ProbeArgs>();
  CLI::App* sub = app.add_subcommand(
      "probe",
      "The twin's air at fixed floor points while the nozzle follows a program: the mean air an\n"
      "object standing there would feel (the CFD's air of the orientation whose wall jet has\n"
      "reached it, formed over time as in the twin; before turbulence, the jet fully on).\n"
      "For checking the twin's moving air against a transient CFD or the rig's anemometers.\n"
      "Program CSV: t_s,pan_deg,tilt_deg (the nozzle's orientation, linear between rows, held\n"
      "outside them); points CSV: x_m,y_m[,z_m] (z default 0.015 m). Writes\n"
      "t_s,point,x_m,y_m,z_m,ux,uy. docs/twin.md, docs/data_formats.md.");
  sub->add_option("--program", args->program, "Nozzle program CSV")->required();
  sub->add_option("--points", args->points, "Probe points CSV")->required();
  sub->add_option("--out", args->out, "Output CSV")->required();
  sub->add_option("--cfd", args->cfd, "The folder of CFD cases")->capture_default_str();
  CLI::Option* on = sub->add_flag(
      "--air-formation", args->formation,
      "The wall jet's formation at the rate of the CFD's short pulses (the default where the\n"
      "cases have the start-up and pulses; given, an error when they have not)");
  sub->add_flag("--no-air-formation", args->no_formation,
                "The reached orientation's whole air at once")
      ->excludes(on);
  sub->add_option("--air-formation-time-scale", args->formation_time_scale,
                  "The formation's times: the pulses' times this, in (0, 10]")
      ->capture_default_str();
  sub->add_option("--air-front-co-flow", args->front_co_flow,
                  "The new front's speed gains this share of the old air flowing its way, [0, 2]")
      ->capture_default_str();
  sub->add_option("--air-front-counter-flow", args->front_counter_flow,
                  "... and loses this share of the old air flowing against it, [0, 2]")
      ->capture_default_str();
  sub->add_option("--timestep", args->settings.timestep_s, "The twin's physics step (s)")
      ->capture_default_str();
  sub->add_option("--interval", args->settings.interval_s,
                  "One record this often (s; a whole number of steps)")
      ->capture_default_str();
  sub->add_option("--end", args->settings.end_s, "Last record's time (s)")->capture_default_str();
  sub->callback([args] { run_probe(*args); });
}

}  // namespace airtwin::cli
