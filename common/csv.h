#pragma once
// A CSV table built in memory and written whole (see output.h).
#include <string>
#include <variant>
#include <vector>

namespace cl {

// A cell: a number (written with 17 significant digits), an integer or text.
// Text with a comma, a double quote or a line break is quoted as RFC 4180
// says ("a, b" -> "\"a, b\"", a quote doubled), so any CSV reader splits it right.
using CsvCell = std::variant<double, long long, std::string>;

// A number where it is known, an empty cell where it is not.
CsvCell cell_if(bool known, double value);

class CsvTable {
 public:
  explicit CsvTable(std::vector<std::string> columns);

  // Appends a row; throws std::invalid_argument if its width is wrong.
  void add_row(const std::vector<CsvCell>& cells);

  std::size_t rows() const { return row_count_; }
  const std::string& text() const { return text_; }

  // Writes the table atomically to `path`.
  void write(const std::string& path) const;

 private:
  std::size_t columns_;
  std::size_t row_count_ = 0;
  std::string text_;
};

}  // namespace cl
