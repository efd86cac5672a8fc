#pragma once
// A strict reader for the project's CSV files (tables, grids, trajectories).
//
// Every problem is reported as an InputError naming the file, the 1-based line and the column:
//   "grid.csv:14: column 'speed': expected a finite number, got 'nan'".
// Accepted: a header line, then data lines with exactly as many comma-separated fields; blank lines
// and lines starting with '#' are skipped; CRLF line ends are tolerated. Rejected: an empty file,
// binary content, a missing required column, a duplicated column, a ragged line.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace airtwin {

class CsvTable {
 public:
  /// Reads and checks a CSV file. `required` columns must be present in the header (any order);
  /// `optional` columns may be present. Any other column is an error, so a typo is never ignored.
  /// Throws InputError.
  static CsvTable read_file(const std::string& path, const std::vector<std::string>& required,
                            const std::vector<std::string>& optional = {});

  /// Same as read_file, from text already in memory; `source` names it in messages.
  static CsvTable parse(std::string_view text, const std::string& source,
                        const std::vector<std::string>& required,
                        const std::vector<std::string>& optional = {});

  const std::string& source() const { return source_; }
  size_t rows() const { return cells_.size(); }
  bool has_column(const std::string& name) const;

  /// The cell at data row `row`, column `name`, as a finite double. Throws InputError naming line
  /// and column when it is not a finite number.
  double number(size_t row, const std::string& name) const;
  /// The raw text of a cell (trimmed).
  const std::string& text(size_t row, const std::string& name) const;
  /// The 1-based line number of data row `row` in the file (for messages).
  size_t line_of(size_t row) const { return lines_[row]; }
  /// "file.csv:LINE" for messages about a row.
  std::string where(size_t row) const;

 private:
  size_t column_index(const std::string& name) const;

  std::string source_;
  std::vector<std::string> header_;
  std::vector<std::vector<std::string>> cells_;
  std::vector<size_t> lines_;
};

/// Parses a finite double from the whole of `text` (no trailing characters); nullopt otherwise.
std::optional<double> parse_finite_double(std::string_view text);

/// Reads a whole file as text; throws InputError when it cannot be opened.
std::string read_text_file(const std::string& path);

}  // namespace airtwin
