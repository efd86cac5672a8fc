#pragma once
// The nozzle's command log: which orientation the servos were told to take, and from when
// (docs/data_formats.md, "Nozzle log"). A rig's servo log and the twin's own logs (`run --out`,
// `render --out`: DIR/nozzle.csv) are written in it; `airtwin trajectories` joins camera tracks
// with it (models/track_join.h).
//
// Header `t,pan_deg,tilt_deg`: one row per command sent (or per servo sample: a row repeating the
// command before it changes nothing), t in s on the camera's clock, strictly increasing; the
// command of a row is in force from its t (inclusive) until the next row's t. Degrees only in the
// file; radians inside.

#include <string>
#include <vector>

#include "models/nozzle_geometry.h"

namespace airtwin {

/// One command: the orientation in force from t_s on (s; radians).
struct NozzleCommand {
  double t_s = 0.0;
  NozzleOrientation nozzle;
};

/// A validated log: at least one command, times strictly increasing.
struct NozzleLog {
  std::string source;                   ///< the file (for messages)
  std::vector<NozzleCommand> commands;  ///< in time order
  std::vector<size_t> lines;            ///< 1-based line of each command in the file

  /// Index of the command in force at t_s (s): the last one with t <= t_s; -1 when t_s is before
  /// the first command.
  long index_at(double t_s) const;
  /// "file:LINE" of command i, for messages.
  std::string where(size_t i) const;
};

class CsvTable;

/// The nozzle command of a CSV row's `pan_deg` and `tilt_deg` columns (radians): finite numbers,
/// tilt in [0, 90) deg. Throws InputError naming the file, line, column and value otherwise. The
/// nozzle log and the trajectory CSV read their commands with it.
NozzleOrientation nozzle_orientation_of_row(const CsvTable& csv, size_t row);

/// Reads and validates a nozzle log: the header (exactly the three columns), finite numbers, tilt
/// in [0, 90) deg, t strictly increasing (a repeated or earlier time is an error naming both
/// lines), at least one row. Throws InputError naming the file, the line and the column.
NozzleLog read_nozzle_log(const std::string& path);
/// Same, from text in memory; `source` names it in messages.
NozzleLog parse_nozzle_log(const std::string& text, const std::string& source);

/// The CSV text of `commands` (6 decimals; deterministic). Their times must increase.
std::string nozzle_log_csv(const std::vector<NozzleCommand>& commands);

/// Appends the command sent at t_s to a log being recorded. A command at the time of the last
/// one replaces it (the last command sent at an instant is the one in force from it); one equal
/// to the command in force is not recorded. t_s must not be before the last command's time.
void record_command(std::vector<NozzleCommand>* log, double t_s, const NozzleOrientation& nozzle);

}  // namespace airtwin
