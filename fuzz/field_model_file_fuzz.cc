// Fuzz target: the field-model JSON of --table M.json (models/field_model_file.h). The reader
// takes a path only, so the input is written to model.json in the scratch folder, beside a valid
// table.csv (the built-in table) that a well-formed input may name.

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "models/field_model_file.h"
#include "models/field_table.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  static const std::filesystem::path model = [] {
    fuzz::write_file(fuzz::scratch_dir() / "table.csv", FieldTable::constructed_table().to_csv());
    return fuzz::scratch_dir() / "model.json";
  }();
  fuzz::write_file(model, fuzz::text_of(data, size));
  fuzz::expect_input_error([&] { (void)read_air_field_model(model.string()); });
  return 0;
}
