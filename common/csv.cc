#include "common/csv.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "common/errors.h"
#include "common/text.h"

namespace airtwin {
namespace {

std::vector<std::string> split_fields(std::string_view line) {
  std::vector<std::string> out;
  size_t start = 0;
  while (true) {
    size_t comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      out.push_back(trim_blanks(line.substr(start)));
      return out;
    }
    out.push_back(trim_blanks(line.substr(start, comma - start)));
    start = comma + 1;
  }
}

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) out += (i ? "," : "") + names[i];
  return out;
}

// Rejects content that is not text: NUL bytes or other control characters are what binary files
// (images, archives, executables) contain and a CSV never does.
void check_is_text(std::string_view text, const std::string& source) {
  for (size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 && c != '\n' && c != '\r' && c != '\t') {
      throw InputError(source + ": not a text CSV file (binary byte 0x" +
                       [&] {
                         char buf[8];
                         std::snprintf(buf, sizeof buf, "%02x", c);
                         return std::string(buf);
                       }() +
                       " at offset " + std::to_string(i) + ")");
    }
  }
}

}  // namespace

std::optional<double> parse_finite_double(std::string_view text) {
  std::string s = trim_blanks(text);
  if (s.empty()) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open file for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(path + ": read error");
  return ss.str();
}

CsvTable CsvTable::read_file(const std::string& path, const std::vector<std::string>& required,
                             const std::vector<std::string>& optional) {
  return parse(read_text_file(path), path, required, optional);
}

CsvTable CsvTable::parse(std::string_view text, const std::string& source,
                         const std::vector<std::string>& required,
                         const std::vector<std::string>& optional) {
  CsvTable t;
  t.source_ = source;
  check_is_text(text, source);

  // Walk the lines; the first non-blank, non-comment line is the header.
  size_t line_no = 0;
  size_t pos = 0;
  bool have_header = false;
  while (pos < text.size()) {
    size_t nl = text.find('\n', pos);
    std::string_view raw =
        text.substr(pos, nl == std::string_view::npos ? text.size() - pos : nl - pos);
    pos = (nl == std::string_view::npos) ? text.size() : nl + 1;
    ++line_no;
    std::string line = trim_blanks(raw);
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields = split_fields(line);
    if (!have_header) {
      t.header_ = fields;
      have_header = true;
      continue;
    }
    if (fields.size() != t.header_.size()) {
      throw InputError(source + ":" + std::to_string(line_no) + ": expected " +
                       std::to_string(t.header_.size()) + " comma-separated fields (" +
                       join(t.header_) + "), got " + std::to_string(fields.size()));
    }
    t.cells_.push_back(std::move(fields));
    t.lines_.push_back(line_no);
  }

  // Check the header: every required column, nothing unknown, nothing twice.
  std::vector<std::string> expected = required;
  expected.insert(expected.end(), optional.begin(), optional.end());
  std::string expect_text = "'";
  expect_text.append(join(required)).append("'");
  if (!optional.empty()) expect_text.append(" (optional: ").append(join(optional)).append(")");
  if (!have_header) throw InputError(source + ": empty file, expected header " + expect_text);
  for (size_t i = 0; i < t.header_.size(); ++i) {
    const std::string& name = t.header_[i];
    if (std::find(expected.begin(), expected.end(), name) == expected.end()) {
      throw InputError(source + ": unknown column '" + name + "' in header, expected " +
                       expect_text);
    }
    if (std::find(t.header_.begin() + i + 1, t.header_.end(), name) != t.header_.end()) {
      throw InputError(source + ": column '" + name + "' appears twice in the header");
    }
  }
  for (const std::string& name : required) {
    if (!t.has_column(name)) {
      throw InputError(source + ": missing column '" + name + "', expected header " + expect_text);
    }
  }
  return t;
}

bool CsvTable::has_column(const std::string& name) const {
  return std::find(header_.begin(), header_.end(), name) != header_.end();
}

size_t CsvTable::column_index(const std::string& name) const {
  auto it = std::find(header_.begin(), header_.end(), name);
  AIRTWIN_DEMAND(it != header_.end());
  return static_cast<size_t>(it - header_.begin());
}

const std::string& CsvTable::text(size_t row, const std::string& name) const {
  AIRTWIN_DEMAND(row < cells_.size());
  return cells_[row][column_index(name)];
}

double CsvTable::number(size_t row, const std::string& name) const {
  const std::string& cell = text(row, name);
  std::optional<double> v = parse_finite_double(cell);
  if (!v) {
    throw InputError(where(row) + ": column '" + name + "': expected a finite number, got '" +
                     (cell.size() > 40 ? cell.substr(0, 40) + "..." : cell) + "'");
  }
  return *v;
}

std::string CsvTable::where(size_t row) const {
  return source_ + ":" + std::to_string(lines_[row]);
}

}  // namespace airtwin
