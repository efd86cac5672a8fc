#include "models/nozzle_log.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/csv.h"
#include "common/errors.h"
#include "common/units.h"

namespace airtwin {

long NozzleLog::index_at(double t_s) const {
  // The first command after t_s, then the one before it.
  const auto after = std::upper_bound(commands.begin(), commands.end(), t_s,
                                      [](double t, const NozzleCommand& c) { return t < c.t_s; });
  return static_cast<long>(after - commands.begin()) - 1;
}

std::string NozzleLog::where(size_t i) const {
  AIRTWIN_DEMAND(i < commands.size());
  return source + ":" + (i < lines.size() ? std::to_string(lines[i]) : "?");
}

NozzleOrientation nozzle_orientation_of_row(const CsvTable& csv, size_t row) {
  const double pan = csv.number(row, "pan_deg"), tilt = csv.number(row, "tilt_deg");
  if (!(tilt >= 0 && tilt < 90)) {
    throw InputError(csv.where(row) + ": column 'tilt_deg': expected a tilt in [0, 90) deg, got " +
                     csv.text(row, "tilt_deg"));
  }
  return {deg_to_rad(pan), deg_to_rad(tilt)};
}

NozzleLog read_nozzle_log(const std::string& path) {
  return parse_nozzle_log(read_text_file(path), path);
}

NozzleLog parse_nozzle_log(const std::string& text, const std::string& source) {
  const CsvTable csv = CsvTable::parse(text, source, {"t", "pan_deg", "tilt_deg"});
  if (csv.rows() == 0) throw InputError(source + ": no nozzle command after the header");
  NozzleLog log;
  log.source = source;
  for (size_t row = 0; row < csv.rows(); ++row) {
    NozzleCommand c;
    c.t_s = csv.number(row, "t");
    c.nozzle = nozzle_orientation_of_row(csv, row);
    // Times strictly increasing: a repeated time leaves two commands for one instant.
    if (!log.commands.empty() && !(c.t_s > log.commands.back().t_s)) {
      const bool repeated = c.t_s == log.commands.back().t_s;
      throw InputError(csv.where(row) + ": column 't': expected a time after line " +
                       std::to_string(log.lines.back()) + "'s " + csv.text(row - 1, "t") +
                       " s (commands in time order, one per instant), got " + csv.text(row, "t") +
                       (repeated ? " again" : ""));
    }
    log.commands.push_back(c);
    log.lines.push_back(csv.line_of(row));
  }
  return log;
}

std::string nozzle_log_csv(const std::vector<NozzleCommand>& commands) {
  std::string out = "t,pan_deg,tilt_deg\n";
  char line[128];
  for (size_t i = 0; i < commands.size(); ++i) {
    AIRTWIN_DEMAND(i == 0 || commands[i].t_s > commands[i - 1].t_s);
    std::snprintf(line, sizeof line, "%.6f,%.6f,%.6f\n", commands[i].t_s,
                  rad_to_deg(commands[i].nozzle.pan_rad), rad_to_deg(commands[i].nozzle.tilt_rad));
    out += line;
  }
  return out;
}

void record_command(std::vector<NozzleCommand>* log, double t_s, const NozzleOrientation& nozzle) {
  AIRTWIN_DEMAND(std::isfinite(t_s));
  AIRTWIN_DEMAND(log->empty() || t_s >= log->back().t_s);
  // The last command sent at an instant is the one in force from it.
  if (!log->empty() && t_s == log->back().t_s) log->pop_back();
  if (!log->empty() && log->back().nozzle.pan_rad == nozzle.pan_rad &&
      log->back().nozzle.tilt_rad == nozzle.tilt_rad) {
    return;
  }
  log->push_back({t_s, nozzle});
}

}  // namespace airtwin
