// The strict CSV reader every data file of the project goes through.

#include "common/csv.h"

#include <gtest/gtest.h>

#include "common/errors.h"

namespace airtwin {
namespace {

std::string error_of(const std::string& text, std::vector<std::string> required,
                     std::vector<std::string> optional = {}) {
  try {
    CsvTable::parse(text, "f.csv", required, optional);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Csv, ReadsColumnsInAnyOrderWithCommentsBlankLinesAndCrlf) {
  const CsvTable t =
      CsvTable::parse("# a comment\r\nb, a\r\n\r\n2,1\r\n 4 ,3\n", "f.csv", {"a", "b"});
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.number(0, "a"), 1);
  EXPECT_EQ(t.number(1, "b"), 4);
  EXPECT_EQ(t.line_of(1), 5u);
  EXPECT_EQ(t.where(0), "f.csv:4");
}

TEST(Csv, OptionalColumns) {
  const CsvTable t = CsvTable::parse("a,g\n1,x\n", "f.csv", {"a"}, {"g", "h"});
  EXPECT_TRUE(t.has_column("g"));
  EXPECT_FALSE(t.has_column("h"));
  EXPECT_EQ(t.text(0, "g"), "x");
}

TEST(Csv, HeaderProblemsNameTheColumn) {
  EXPECT_NE(error_of("a\n1\n", {"a", "b"}).find("missing column 'b'"), std::string::npos);
  EXPECT_NE(error_of("a,b,c\n1,2,3\n", {"a", "b"}).find("unknown column 'c'"), std::string::npos);
  EXPECT_NE(error_of("a,a\n1,2\n", {"a"}).find("appears twice"), std::string::npos);
  EXPECT_NE(error_of("", {"a"}).find("f.csv: empty file"), std::string::npos);
}

TEST(Csv, RaggedLineNamesTheLine) {
  EXPECT_NE(error_of("a,b\n1,2\n3\n", {"a", "b"}).find("f.csv:3: expected 2"), std::string::npos);
}

TEST(Csv, NumbersMustBeFiniteAndWhole) {
  const CsvTable t = CsvTable::parse("a\nnan\ninf\n1e400\n1.5x\n\"2\"\n-0.25e-3\n", "f.csv", {"a"});
  for (size_t r = 0; r < 5; ++r) {
    try {
      t.number(r, "a");
      FAIL() << "row " << r << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("f.csv:" + std::to_string(r + 2) + ": column 'a'"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_DOUBLE_EQ(t.number(5, "a"), -0.25e-3);
  EXPECT_FALSE(parse_finite_double(""));
  EXPECT_FALSE(parse_finite_double("  "));
  EXPECT_EQ(*parse_finite_double(" 3 "), 3.0);
}

TEST(Csv, BinaryContentIsRejected) {
  const std::string bin("a,b\n1,\0\x01\x02", 9);
  EXPECT_NE(error_of(bin, {"a", "b"}).find("not a text CSV file"), std::string::npos);
}

TEST(Csv, MissingFileIsNamed) {
  try {
    CsvTable::read_file("/no/such/file.csv", {"a"});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "/no/such/file.csv: cannot open file for reading");
  }
}

}  // namespace
}  // namespace airtwin
