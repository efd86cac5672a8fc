#include "app/cfd_source.h"

#include <filesystem>
#include <system_error>
#include <utility>
#include <vector>

#include "common/errors.h"

namespace airtwin::cli {

CfdField read_cfd_source(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) return CfdField::read_dir(path);
  // One case: its header names its data file.
  if (fs::is_regular_file(path, ec) && fs::path(path).extension() == ".json") {
    std::vector<CfdCase> cases;
    cases.push_back(CfdCase::read(path));
    return CfdField(std::move(cases));
  }
  throw InputError(path + ": expected a folder of CFD cases or a case's .json header");
}

}  // namespace airtwin::cli
