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

}  // namespace airtwin::testing
