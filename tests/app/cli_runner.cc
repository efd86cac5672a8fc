#include "tests/app/cli_runner.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "tests/support/scratch_dir.h"

namespace airtwin::testing {
std::string scratch_dir(const std::string& name) { return fresh_scratch_dir(name); }

CliResult run_airtwin(const std::string& args) {
  const std::string dir = scratch_dir("cli_io");
  const std::string out = dir + "/stdout", err = dir + "/stderr";
  const std::string cmd = std::string("'") + AIRTWIN_BINARY + "' " + args + " </dev/null >'" + out +
                          "' 2>'" + err + "'";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = file_text(out);
  r.err = file_text(err);
  std::filesystem::remove_all(dir);
  return r;
}

std::string file_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int count_lines(const std::string& text) {
  int n = 0;
  for (char c : text) n += (c == '\n');
  if (!text.empty() && text.back() != '\n') ++n;
  return n;
}

std::string constructed_table() {
  return "'" + std::string(AIRTWIN_SOURCE_DIR) + "/models/data/constructed_field_table.csv'";
}

std::string mirror_flags() {
  return " --air model --drag eq8 --table " + constructed_table() + " ";
}

const std::string& line_with_wide_start() {
  static const std::string path = [] {
    std::string text = file_text(std::string(AIRTWIN_SOURCE_DIR) + "/scenes/line.yaml");
    const std::string paper = "  variance0_m2: 20.9e-4\n";
    const size_t at = text.find(paper);
    if (at == std::string::npos) throw std::runtime_error("scenes/line.yaml: no " + paper);
    text.replace(at, paper.size(), "  variance0_m2: 0.02\n  scan_step_m: 0.1\n");
    const std::string clearance = "  sweep_clearance_m: 0.10\n";
    const size_t c = text.find(clearance);
    if (c == std::string::npos) throw std::runtime_error("scenes/line.yaml: no " + clearance);
    text.replace(c, clearance.size(), "  sweep_clearance_m: 0\n");
    const std::string cheapest = "  keep_cheapest: true\n";
    const size_t k = text.find(cheapest);
    if (k == std::string::npos) throw std::runtime_error("scenes/line.yaml: no " + cheapest);
    text.replace(k, cheapest.size(), "  keep_cheapest: false\n");
    const std::string file = scratch_dir("line_with_wide_start") + "/line.yaml";
    std::ofstream(file, std::ios::binary) << text;
    return file;
  }();
  return path;
}

}  // namespace airtwin::testing
