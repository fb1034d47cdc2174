// Results as data: a run's rows go to a sink that receives the column names
// once, then one row of numbers at a time (the time first). The CSV writer
// of `kanegen simulate`, the sweep's metrics, the Python module and the
// tests are all sinks: no one formats rows as text to read them back.
#pragma once

#include <cstddef>
#include <ostream>
#include <string>
#include <vector>

namespace kanegen {

class RowSink {
 public:
  virtual ~RowSink() = default;
  /// The columns of every row that follows (t first), once, before the rows.
  virtual void begin(const std::vector<std::string>& columns) = 0;
  /// One row: `n` values, as many as the columns.
  virtual void row(const double* values, std::size_t n) = 0;
};

/// The CSV of interface.md: a header line, then each row at 17 significant digits.
class CsvRowWriter final : public RowSink {
 public:
  explicit CsvRowWriter(std::ostream& out) : out_(out) {}
  void begin(const std::vector<std::string>& columns) override;
  void row(const double* values, std::size_t n) override;

 private:
  std::ostream& out_;
  std::string line_;
};

/// The rows kept in memory, row-major, with their column names.
class RowTable final : public RowSink {
 public:
  void begin(const std::vector<std::string>& columns) override { columns_ = columns; values_.clear(); }
  void row(const double* values, std::size_t n) override { values_.insert(values_.end(), values, values + n); }

  const std::vector<std::string>& columns() const { return columns_; }
  std::size_t rows() const { return columns_.empty() ? 0 : values_.size() / columns_.size(); }
  double at(std::size_t row, std::size_t column) const { return values_[row * columns_.size() + column]; }
  /// The index of a column by name; -1 if there is none.
  int column_index(const std::string& name) const;
  /// One column's values over the rows; throws std::out_of_range for an unknown name.
  std::vector<double> column(const std::string& name) const;
  std::vector<double> column(std::size_t c) const;
  const std::vector<double>& data() const { return values_; }

 private:
  std::vector<std::string> columns_;
  std::vector<double> values_;
};

/// Every row to two sinks (a run's table and its CSV file).
class TeeRowSink final : public RowSink {
 public:
  TeeRowSink(RowSink& a, RowSink& b) : a_(a), b_(b) {}
  void begin(const std::vector<std::string>& columns) override { a_.begin(columns), b_.begin(columns); }
  void row(const double* values, std::size_t n) override { a_.row(values, n), b_.row(values, n); }

 private:
  RowSink &a_, &b_;
};

}  // namespace kanegen
