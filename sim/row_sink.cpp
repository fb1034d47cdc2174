#include "sim/row_sink.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace kanegen {

void CsvRowWriter::begin(const std::vector<std::string>& columns) {
  for (std::size_t c = 0; c < columns.size(); ++c) out_ << (c ? "," : "") << columns[c];
  out_ << '\n';
}

void CsvRowWriter::row(const double* values, std::size_t n) {
  line_.clear();
  for (std::size_t k = 0; k < n; ++k) {
    if (k) line_ += ',';
    fmt::format_to(std::back_inserter(line_), "{:.17g}", values[k]);
  }
  out_ << line_ << '\n';
}

int RowTable::column_index(const std::string& name) const {
  const auto it = std::find(columns_.begin(), columns_.end(), name);
  return it == columns_.end() ? -1 : static_cast<int>(it - columns_.begin());
}

std::vector<double> RowTable::column(std::size_t c) const {
  std::vector<double> v(rows());
  for (std::size_t r = 0; r < v.size(); ++r) v[r] = at(r, c);
  return v;
}

std::vector<double> RowTable::column(const std::string& name) const {
  const int c = column_index(name);
  if (c < 0) throw std::out_of_range("no column '" + name + "'");
  return column(static_cast<std::size_t>(c));
}

}  // namespace kanegen
