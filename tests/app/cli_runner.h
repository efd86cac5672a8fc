#pragma once
// Runs the `airtwin` binary as a user would, capturing exit status, stdout and stderr.

#include <string>

namespace airtwin::testing {

struct CliResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

/// Runs `airtwin <args>` through /bin/sh (args are shell words), stdin from /dev/null.
CliResult run_airtwin(const std::string& args);

/// A fresh empty directory under the system temp dir, unique to this process and `name`.
std::string scratch_dir(const std::string& name);

/// The bytes of the file at `path` ("" if it cannot be read).
std::string file_text(const std::string& path);

/// Number of lines in `text` (a trailing newline does not start a new line).
int count_lines(const std::string& text);

/// The constructed table's file (models/data/constructed_field_table.csv), quoted for the shell.
std::string constructed_table();

/// The mirror twin of the constructed table as shell words, with spaces around them: its air is
/// eqs. (1)-(3) with that table and its drag eq. (8) (" --air model --drag eq8 --table FILE "). The
/// hidden-effect tests were measured in it; data collected in it are analysed with --table
/// constructed_table().
std::string mirror_flags();

/// scenes/line.yaml with the wider CEM start the file had before it took the paper's (Sigma0
/// 0.02 m^2 and a floor scan when the line search is blind) and without the later sweep
/// clearance and cheapest candidate, the runs the tests' figures were measured on, written once per
/// process into a scratch folder: in the mirror twin its tracer moves from the first decision (with
/// the paper's settings its first push at seed 1 comes after 13 s), which tests of the first
/// seconds need.
const std::string& line_with_wide_start();

}  // namespace airtwin::testing
