#pragma once
// What every fuzz target shares: the parsers' contract for bad input (one InputError, or one of
// its subclasses FieldError and UsageError) is the expected outcome and ends an input quietly;
// any other exception is a finding, as are crashes, sanitizer reports, leaks and hangs, which
// libFuzzer catches itself. Parsers that read only from a path get the input written to a file in
// a scratch folder of the process's own.

#include <cxxabi.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <typeinfo>

#include "common/errors.h"

namespace airtwin::fuzz {

/// The input as text (any bytes, NULs included).
inline std::string text_of(const uint8_t* data, size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

/// Runs `parse`. An InputError is the contract and is swallowed (printed when the environment
/// sets AIRTWIN_FUZZ_SHOW_ERRORS, to see why a seed is rejected); any other exception escaping is
/// reported with its type and message and aborts, so that libFuzzer keeps the input as a crash.
template <class Parse>
void expect_input_error(Parse&& parse) {
  try {
    parse();
  } catch (const InputError& e) {
    if (std::getenv("AIRTWIN_FUZZ_SHOW_ERRORS") != nullptr) {
      std::fprintf(stderr, "fuzz: InputError: %s\n", e.what());
    }
  } catch (const std::exception& e) {
    int status = 0;
    char* type = abi::__cxa_demangle(typeid(e).name(), nullptr, nullptr, &status);
    std::fprintf(stderr, "fuzz: %s escaped the parser (expected InputError): %s\n",
                 status == 0 ? type : typeid(e).name(), e.what());
    std::free(type);
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz: a non-std exception escaped the parser (expected InputError)\n");
    std::abort();
  }
}

/// "<TMPDIR>/airtwin_fuzz_<pid>": created on first use, removed with its contents at exit
/// (libFuzzer exits through exit() after its runs; after a crash the folder stays).
inline const std::filesystem::path& scratch_dir() {
  struct Dir {
    std::filesystem::path path;
    Dir()
        : path(std::filesystem::temp_directory_path() /
               ("airtwin_fuzz_" + std::to_string(::getpid()))) {
      std::filesystem::create_directories(path);
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

/// Writes `bytes` to `path` (replacing it); aborts when the file cannot be written, which is a
/// broken fuzzing set-up rather than a finding.
inline void write_file(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
}

}  // namespace airtwin::fuzz
