#pragma once
// A fresh, empty folder per test process and name under the system's temporary folder (ctest runs
// test cases in parallel processes: the process id keeps them apart).

#include <unistd.h>

#include <filesystem>
#include <string>

namespace airtwin::testing {

/// "<temp>/airtwin_test_<pid>_<name>", emptied and created.
inline std::string fresh_scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("airtwin_test_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

}  // namespace airtwin::testing
