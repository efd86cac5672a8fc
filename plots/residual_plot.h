#pragma once
// Pictures of a discrepancy analysis for people (models/discrepancy.h): the baseline's residuals
// (prediction minus measurement, split along and across the radial direction from s) against
// distance from s, alpha, time since the command changed and speed, with the binned means; and a
// floor map of where the residuals are large.

#include <string>

#include "models/discrepancy.h"

namespace airtwin::plots {

/// Writes DIR/residuals_distance.png, residuals_alpha.png, residuals_time_since_command.png,
/// residuals_speed.png and residuals_floor.png. Throws InputError when a file cannot be written.
void write_residual_plots(const DiscrepancyReport& report, const std::string& dir);

/// Writes `path` (PNG): the chosen nonparametric correction of what is left (report.corrections),
/// a pair of maps (radial and across) for a floor or s-relative feature, curves for time; nothing
/// when no correction was chosen. Throws InputError when the file cannot be written.
void write_correction_plot(const DiscrepancyReport& report, const std::string& path);

}  // namespace airtwin::plots
