#include "common/csv.h"

#include <stdexcept>

#include "common/output.h"

namespace cl {

namespace {
// RFC 4180: text with a comma, a quote or a line break goes in quotes, its
// quotes doubled; any other text is written as it is.
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string result = "\"";
  for (const char c : text) result += c == '"' ? std::string("\"\"") : std::string(1, c);
  return result + '"';
}
}  // namespace

CsvCell cell_if(bool known, double value) { return known ? CsvCell{value} : CsvCell{std::string()}; }

CsvTable::CsvTable(std::vector<std::string> columns) : columns_(columns.size()) {
  for (std::size_t c = 0; c < columns.size(); ++c) text_ += (c ? "," : "") + csv_field(columns[c]);
  text_ += '\n';
}

void CsvTable::add_row(const std::vector<CsvCell>& cells) {
  if (cells.size() != columns_) {
    throw std::invalid_argument("CsvTable::add_row: " + std::to_string(cells.size()) + " cells for " +
                                std::to_string(columns_) + " columns");
  }
  for (std::size_t c = 0; c < cells.size(); ++c) {
    if (c) text_ += ',';
    if (const double* number = std::get_if<double>(&cells[c])) {
      text_ += format_double(*number);
    } else if (const long long* integer = std::get_if<long long>(&cells[c])) {
      text_ += std::to_string(*integer);
    } else {
      text_ += csv_field(std::get<std::string>(cells[c]));
    }
  }
  text_ += '\n';
  ++row_count_;
}

void CsvTable::write(const std::string& path) const { write_file_atomic(path, text_); }

}  // namespace cl
