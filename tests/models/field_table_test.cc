// The eq. (3) coefficient table: loading, validation of every kind of malformed file, round trip.

#include "models/field_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/errors.h"
#include "common/units.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

std::string join_lines(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

// A valid table's text to mutate: line 0 is the header, line 1 + 360 i + a is tilt i, alpha a.
std::string valid_text() { return FieldTable::constructed_table().to_csv(); }

// Expects parse_csv to throw an InputError whose message contains every fragment.
void expect_error(const std::string& text, std::initializer_list<const char*> fragments) {
  try {
    FieldTable::parse_csv(text, "t.csv");
    FAIL() << "no error for a malformed table";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
    for (const char* f : fragments) EXPECT_NE(msg.find(f), std::string::npos) << msg;
  }
}

TEST(FieldTable, DefaultTableHasThePapersTilts) {
  const FieldTable& t = FieldTable::constructed_table();
  ASSERT_EQ(t.n_tilts(), 3u);
  EXPECT_NEAR(rad_to_deg(t.tilts_rad()[0]), 0.0, 1e-12);
  EXPECT_NEAR(rad_to_deg(t.tilts_rad()[1]), 22.5, 1e-12);
  EXPECT_NEAR(rad_to_deg(t.tilts_rad()[2]), 45.0, 1e-12);
}

TEST(FieldTable, CsvRoundTripIsExact) {
  const FieldTable& t = FieldTable::constructed_table();
  const std::string text = t.to_csv();
  const FieldTable back = FieldTable::parse_csv(text, "mem");
  EXPECT_EQ(back.to_csv(), text);
  const auto path = std::filesystem::path(testing::scratch_root()) / "table_roundtrip.csv";
  t.save_csv(path.string());
  EXPECT_EQ(FieldTable::load_csv(path.string()).to_csv(), text);
  std::filesystem::remove(path);
}

TEST(FieldTable, Eq3SpeedIsTheTwoTermExponential) {
  const FieldCoefficients c{4.0, -1.0, -25.0};
  EXPECT_EQ(c.speed(0.0), 0.0);
  EXPECT_NEAR(c.speed(0.13), 4.0 * (std::exp(-0.13) - std::exp(-3.25)), 1e-15);
  // Peak at ln(b3/b2) / (b2 - b3) (physics note): 0.1341 m, ~3.36 m/s.
  const double r_peak = std::log(25.0) / 24.0;
  EXPECT_NEAR(c.speed(r_peak), 3.36, 0.01);
  EXPECT_GT(c.speed(r_peak), c.speed(r_peak - 1e-3));
  EXPECT_GT(c.speed(r_peak), c.speed(r_peak + 1e-3));
}

TEST(FieldTable, RejectsEmptyFile) {
  expect_error("", {"t.csv", "empty file", "tilt_deg,alpha_deg,b1,b2,b3"});
  expect_error("\n\n# only a comment\n", {"t.csv", "empty file"});
  expect_error("tilt_deg,alpha_deg,b1,b2,b3\n", {"t.csv", "no data rows"});
}

TEST(FieldTable, RejectsBinaryGarbage) {
  std::string garbage = "\x89PNG\r\n\x1a\n";
  garbage += std::string("\0\0\0\rIHDR", 8);
  expect_error(garbage, {"t.csv", "not a text CSV file"});
}

TEST(FieldTable, RejectsMissingOrUnknownColumn) {
  auto l = lines_of(valid_text());
  std::vector<std::string> no_b3;
  for (const std::string& line : l) no_b3.push_back(line.substr(0, line.rfind(',')));
  expect_error(join_lines(no_b3), {"t.csv", "missing column 'b3'"});
  l[0] = "tilt_deg,alpha_deg,b1,b2,b4";
  expect_error(join_lines(l), {"t.csv", "unknown column 'b4'"});
}

TEST(FieldTable, RejectsNanAndNonNumbers) {
  auto l = lines_of(valid_text());
  l[5] = "0,4,nan,-1,-25";
  expect_error(join_lines(l), {"t.csv:6", "column 'b1'", "finite number", "nan"});
  l = lines_of(valid_text());
  l[7] = "0,6,3.4,abc,-25";
  expect_error(join_lines(l), {"t.csv:8", "column 'b2'"});
  l = lines_of(valid_text());
  l[7] = "0,6,3.4,-1";
  expect_error(join_lines(l), {"t.csv:8", "expected 5 comma-separated fields"});
}

TEST(FieldTable, RejectsMissingTilt) {
  // Drop the whole 22.5 deg block: two tilts are not enough for Makima in tilt.
  auto l = lines_of(valid_text());
  l.erase(l.begin() + 1 + 360, l.begin() + 1 + 720);
  expect_error(join_lines(l), {"t.csv", "2 tilt(s)", "at least 3"});
  // A tilt whose block is cut short.
  l = lines_of(valid_text());
  l.erase(l.begin() + 1 + 360 + 200, l.begin() + 1 + 720);
  expect_error(join_lines(l), {"t.csv", "starts before tilt", "22.5"});
  // The last tilt cut short.
  l = lines_of(valid_text());
  l.pop_back();
  expect_error(join_lines(l), {"t.csv", "ends at alpha 358"});
}

TEST(FieldTable, RejectsUnsortedOrDuplicateAlpha) {
  auto l = lines_of(valid_text());
  std::swap(l[10], l[11]);
  expect_error(join_lines(l), {"t.csv:11", "alpha_deg", "missing", "expected 9"});
  l = lines_of(valid_text());
  l[12] = l[11];  // alpha 10 twice
  expect_error(join_lines(l), {"t.csv:13", "out of order or duplicated", "expected 11"});
  l = lines_of(valid_text());
  l[3] = "0,2.5,3.4,-1,-25";  // not a whole degree
  expect_error(join_lines(l), {"t.csv:4", "alpha_deg"});
}

TEST(FieldTable, RejectsBadTiltOrder) {
  auto l = lines_of(valid_text());
  // Swap the 22.5 and 45 blocks: tilts must increase.
  std::vector<std::string> swapped(l.begin(), l.begin() + 361);
  swapped.insert(swapped.end(), l.begin() + 721, l.end());
  swapped.insert(swapped.end(), l.begin() + 361, l.begin() + 721);
  expect_error(join_lines(swapped), {"t.csv:722", "increasing"});
  l = lines_of(valid_text());
  for (size_t i = 721; i < l.size(); ++i) l[i].replace(0, 2, "95");
  expect_error(join_lines(l), {"t.csv:722", "tilt_deg", "[0, 90)"});
}

TEST(FieldTable, LoadNamesAMissingFile) {
  try {
    FieldTable::load_csv("/nonexistent/dir/table.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/table.csv: cannot open"),
              std::string::npos);
  }
}

}  // namespace
}  // namespace airtwin
