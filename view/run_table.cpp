#include "view/run_table.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "model/diagnostics.hpp"

namespace kanegen {

int RunTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  return -1;
}

namespace {

std::vector<std::string> split_commas(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    out.push_back(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

RunTable read_run_table(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(Diagnostic{path, 0, "", "cannot open the run's CSV"});
  RunTable run;
  run.path = path;
  auto refuse = [&](int line, const std::string& field, const std::string& why) {
    throw InputError(Diagnostic{path, line, field, why});
  };
  std::string line;
  if (!std::getline(in, line)) refuse(0, "", "empty file; expected a CSV written by kanegen simulate");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  run.names = split_commas(line);
  std::set<std::string> seen;
  for (std::size_t c = 0; c < run.names.size(); ++c) {
    if (run.names[c].empty()) refuse(1, "header", fmt::format("column {} has no name", c + 1));
    if (!seen.insert(run.names[c]).second) refuse(1, "header", fmt::format("column '{}' appears twice", run.names[c]));
  }
  if (run.names.front() != "t") refuse(1, "header", fmt::format("the first column is '{}'; expected t", run.names.front()));
  std::vector<std::vector<double>> rows;
  for (int number = 2; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const auto cells = split_commas(line);
    if (cells.size() != run.names.size())
      refuse(number, "", fmt::format("{} values; the header has {} columns", cells.size(), run.names.size()));
    std::vector<double> row(cells.size());
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const char* s = cells[c].c_str();
      char* end = nullptr;
      row[c] = std::strtod(s, &end);
      if (end == s || *end != '\0' || !std::isfinite(row[c]))
        refuse(number, run.names[c], fmt::format("'{}' is not a finite number", cells[c]));
    }
    if (!rows.empty() && row[0] < rows.back()[0])
      refuse(number, "t", fmt::format("time {} before the previous row's {}", row[0], rows.back()[0]));
    rows.push_back(std::move(row));
  }
  if (rows.empty()) refuse(0, "", "no rows after the header");
  run.rows.resize(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(run.names.size()));
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (std::size_t c = 0; c < rows[r].size(); ++c) run.rows(r, c) = rows[r][c];
  return run;
}

std::vector<RunEvent> read_events_table(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(Diagnostic{path, 0, "", "cannot open the events table"});
  std::string line;
  std::getline(in, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line.rfind("t,name,action,bodies", 0) != 0)
    throw InputError(Diagnostic{path, 1, "header",
                                fmt::format("'{}'; expected t,name,action,bodies,energy_lost (kanegen simulate --events)",
                                            line.substr(0, 80))});
  std::vector<RunEvent> events;
  for (int number = 2; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const auto cells = split_commas(line);
    if (cells.size() < 4) throw InputError(Diagnostic{path, number, "", "fewer than 4 values (t, name, action, bodies)"});
    RunEvent e;
    char* end = nullptr;
    e.t = std::strtod(cells[0].c_str(), &end);
    if (end == cells[0].c_str() || *end != '\0' || !std::isfinite(e.t))
      throw InputError(Diagnostic{path, number, "t", fmt::format("'{}' is not a finite number", cells[0])});
    e.name = cells[1];
    e.action = cells[2];
    std::istringstream bodies(cells[3]);
    for (std::string b; bodies >> b;) e.bodies.push_back(b);
    events.push_back(std::move(e));
  }
  return events;
}

std::vector<int> state_columns(const RunTable& run, const Model& model) {
  std::vector<int> cols;
  for (const auto* names : {&model.q_names, &model.u_names})
    for (const std::string& n : *names) {
      const int c = run.column(n);
      if (c < 0)
        throw InputError(Diagnostic{run.path, 1, "header",
                                    fmt::format("no column '{}': the run is not of model {} (its state is {} "
                                                "coordinates and {} speeds)",
                                                n, model.name, model.q_names.size(), model.u_names.size())});
      cols.push_back(c);
    }
  return cols;
}

State run_state(const RunTable& run, const Model& model, const std::vector<int>& columns, int row) {
  const int nq = static_cast<int>(model.q_names.size()), nu = static_cast<int>(model.u_names.size());
  State s;
  s.t = run.rows(row, 0);
  s.q.resize(nq);
  s.u.resize(nu);
  for (int i = 0; i < nq; ++i) s.q(i) = run.rows(row, columns[i]);
  for (int i = 0; i < nu; ++i) s.u(i) = run.rows(row, columns[nq + i]);
  return s;
}

}  // namespace kanegen
