// Fuzz target: a CFD case of data/cfd/ (models/cfd_field.h): its JSON header and the float32 data
// file the header names. The reader takes the header's path only, so the input is split at its
// first NUL byte: the header before it goes to case.json in the scratch folder, the bytes after it
// to case.f32 beside it (empty when there is no NUL). A case the reader accepts must answer
// queries on and off its grid.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz/fuzz_support.h"
#include "models/cfd_field.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  static const std::filesystem::path header = fuzz::scratch_dir() / "case.json";
  static const std::filesystem::path values = fuzz::scratch_dir() / "case.f32";
  const std::string input = fuzz::text_of(data, size);
  const size_t nul = input.find('\0');
  fuzz::write_file(header, std::string_view(input).substr(0, nul));
  fuzz::write_file(values, nul == std::string::npos ? std::string_view()
                                                    : std::string_view(input).substr(nul + 1));
  fuzz::expect_input_error([&] {
    const CfdCase c = CfdCase::read(header.string());
    for (const double x : {c.stagnation_x_m(), 0.0, -0.3, 2.0}) {
      for (const double y : {0.0, 0.05, -0.2}) {
        for (const double z : {0.0, c.heights_m().front(), 1.0}) {
          (void)c.at(x, y, z);
          (void)c.vertical_at(x, y, z);
          (void)c.pressure_gradient_at(x, y, z);
        }
      }
    }
  });
  return 0;
}
