#pragma once
// Scratch folders of a test process under the system's temporary folder. ctest runs test cases in
// parallel processes: the process id keeps them apart. Everything a process writes there goes
// when it exits normally, so that repeated runs do not fill the disk (a detection dataset is
// ~70 MB); AIRTWIN_KEEP_SCRATCH=1 keeps it for a look after a failure.

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace airtwin::testing {

/// "<temp>/airtwin_test_<pid>": this process's folder, created on first use, removed with its
/// contents at normal exit unless AIRTWIN_KEEP_SCRATCH is set.
inline const std::string& scratch_root() {
  struct Root {
    std::string path;
    Root()
        : path((std::filesystem::temp_directory_path() /
                ("airtwin_test_" + std::to_string(::getpid())))
                   .string()) {
      std::filesystem::create_directories(path);
    }
    ~Root() {
      if (std::getenv("AIRTWIN_KEEP_SCRATCH") != nullptr) return;
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Root root;
  return root.path;
}

/// "<scratch root>/<name>", emptied and created.
inline std::string fresh_scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::path(scratch_root()) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

}  // namespace airtwin::testing
