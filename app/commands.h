#pragma once
// Each subcommand of `airtwin` registers itself on the top-level CLI11 app. A command's callback
// throws InputError for bad input; main() turns that into one line on stderr and exit status 1.

#include <CLI/CLI.hpp>

namespace airtwin::cli {

void add_field_command(CLI::App& app);      // eq. (1)-(3) field on a grid: CSV + PNG
void add_aim_command(CLI::App& app);        // desired stagnation point -> (pan, tilt)
void add_fitfield_command(CLI::App& app);   // Appendix C: fit the coefficient table to grids
void add_maketable_command(CLI::App& app);  // construct the default table from wall-jet physics
void add_hotwire_command(CLI::App& app);    // Appendix A: a hot-wire campaign simulated from CFD
void add_probe_command(CLI::App& app);      // the twin's moving air at fixed points over a program
void add_identify_command(CLI::App& app);   // section IV: SINDy on trajectories -> model.json
void add_collect_command(CLI::App& app);    // Appendix D protocol in the twin -> trajectory CSV
void add_calibrate_dynamics_command(CLI::App& app);  // tune twin drag/friction to eq. (8)
void add_run_command(CLI::App& app);          // section V: a scenario in closed loop in the twin
void add_view_command(CLI::App& app);         // the same run shown live in a window
void add_scene_command(CLI::App& app);        // the twin's scene as MJCF files for MuJoCo
void add_batch_command(CLI::App& app);        // scenarios x seeds in parallel, resumable, shards
void add_batch_merge_command(CLI::App& app);  // the shards of a batch -> one report
void add_render_command(CLI::App& app);     // synthetic camera dataset of a scenario: frames, truth
void add_calibrate_command(CLI::App& app);  // camera model from calibration-target frames
void add_detect_command(CLI::App& app);     // detection + tracking on frames -> detections.csv
void add_discrepancy_command(CLI::App& app);   // model vs data: causes, extended model, gain
void add_trajectories_command(CLI::App& app);  // detections + nozzle log -> trajectory CSV
void add_region_command(CLI::App& app);        // where the line search's pushes move objects

}  // namespace airtwin::cli
