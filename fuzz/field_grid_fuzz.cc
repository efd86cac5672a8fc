// Fuzz target: the field grids of fitfield (models/field_grid.h), each input read as a measured
// grid and as a CFD grid. What the reader accepts passes validation and the writer writes.

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "models/field_grid.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  const std::string text = fuzz::text_of(data, size);
  for (const GridKind kind : {GridKind::kMeasured, GridKind::kSimulated}) {
    fuzz::expect_input_error([&] {
      const FieldGrid grid = parse_field_grid(text, "fuzz.csv", kind);
      validate_field_grid(grid);
      (void)field_grid_to_csv(grid);
    });
  }
  return 0;
}
