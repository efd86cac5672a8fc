// Field-model files: a table CSV read with the paper's eq. (2), a field-model JSON with its own
// a1, a2 (checked against eq. (2) itself), round trip, and one clear error per bad file.

#include "models/field_model_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "common/errors.h"
#include "common/units.h"
#include "models/field_table.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

std::string error_of(const std::string& path) {
  try {
    read_air_field_model(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(FieldModelFile, TableCsvHasThePapersEqTwoAndJsonItsOwn) {
  const std::string dir = testing::fresh_scratch_dir("field_model_file");
  FieldTable::constructed_table().save_csv(dir + "/table.csv");
  const AirFieldModel csv = read_air_field_model(dir + "/table.csv");
  EXPECT_EQ(csv.geometry().a1, 0.1);
  EXPECT_EQ(csv.geometry().a2, 2.33);

  NozzleGeometry g;
  g.a1 = 0.181;
  g.a2 = 1.34;
  write_air_field_model(dir + "/model.json", g, "table.csv");
  EXPECT_TRUE(is_field_model_file(dir + "/model.json"));
  const AirFieldModel json = read_air_field_model(dir + "/model.json");
  EXPECT_EQ(json.geometry().a1, 0.181);
  EXPECT_EQ(json.geometry().a2, 1.34);
  // eq. (2) itself: |c - s| = a1 |c|^a2, on the model's own c and s.
  for (double tilt_deg : {15.0, 22.5, 45.0}) {
    const OrientedField f = json.at({0.7, deg_to_rad(tilt_deg)});
    const double c = f.projection_point().norm();
    EXPECT_NEAR((f.projection_point() - f.stagnation_point()).norm(), 0.181 * std::pow(c, 1.34),
                1e-9)
        << tilt_deg;
  }
  // The same table either way.
  EXPECT_EQ(json.table().to_csv(), csv.table().to_csv());
}

TEST(FieldModelFile, BadFilesAreOneClearError) {
  const std::string dir = testing::fresh_scratch_dir("field_model_file_bad");
  FieldTable::constructed_table().save_csv(dir + "/table.csv");
  auto write = [&](const std::string& text) {
    std::ofstream(dir + "/m.json") << text;
    return error_of(dir + "/m.json");
  };
  EXPECT_NE(write("{").find("not JSON"), std::string::npos);
  // A number past double's range is not JSON to nlohmann, an out_of_range error, not a parse
  // error (fuzz/field_model_file_fuzz.cc).
  EXPECT_NE(write(R"({"eq2": {"a1": 1e999}})").find("not JSON"), std::string::npos);
  EXPECT_NE(write(R"({"format": "x"})").find("format: expected"), std::string::npos);
  const std::string head = R"({"format": "airtwin-field-model 1", )";
  EXPECT_NE(write(head + R"("table": "table.csv"})").find("missing field 'eq2'"),
            std::string::npos);
  EXPECT_NE(write(head + R"("eq2": {"a1": 0.1}, "table": "table.csv"})").find("eq2.a2"),
            std::string::npos);
  EXPECT_NE(write(head + R"("eq2": {"a1": 0.1, "a2": 0.5}, "table": "table.csv"})").find("eq2: "),
            std::string::npos);
  EXPECT_NE(write(head + R"("eq2": {"a1": 0.1, "a2": 2}})").find("table: expected"),
            std::string::npos);
  EXPECT_NE(write(head + R"("eq2": {"a1": 0.1, "a2": 2}, "table": "none.csv"})").find("none.csv"),
            std::string::npos);
  EXPECT_NE(error_of(dir + "/absent.json").find("cannot open"), std::string::npos);
}

}  // namespace
}  // namespace airtwin
