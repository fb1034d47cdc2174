#include "fea/nastran_punch.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include "fea/nastran_cards.hpp"
#include "model/diagnostics.hpp"

namespace kanegen::nastran {

namespace {

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

std::vector<Mode> read_punch_modes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(Diagnostic{path, 0, "", "cannot read the punch file"});
  auto refuse = [&](int line, const std::string& why) { throw InputError(Diagnostic{path, line, "", why}); };
  std::map<int, Mode> modes;
  bool eigenvectors = false;  // inside an $EIGENVECTOR block
  bool complex = false;       // the block's output is complex
  Mode* mode = nullptr;       // the block's mode ($EIGENVALUE line)
  Eigen::Matrix<double, 6, 1>* row = nullptr;  // the grid whose -CONT- row comes next
  int row_grid = 0;
  int line = 0;
  for (std::string s; std::getline(in, s);) {
    ++line;
    if (!s.empty() && s.back() == '\r') s.pop_back();
    if (s.size() > 72) s.resize(72);  // columns 73-80: the line counter
    if (starts_with(s, "$")) {
      if (row) refuse(line, fmt::format("grid {}: its -CONT- row (R1 R2 R3) is missing", row_grid));
      row = nullptr;
      std::string key = s.substr(1);
      key.erase(key.find_last_not_of(' ') + 1);
      if (starts_with(key, "TITLE")) {  // a new block
        eigenvectors = complex = false;
        mode = nullptr;
      } else if (starts_with(key, "SUBTITLE") || starts_with(key, "LABEL") || starts_with(key, "SUBCASE ID") ||
                 starts_with(key, "ELEMENT TYPE")) {
      } else if (key == "REAL OUTPUT") {
        complex = false;
      } else if (key == "REAL-IMAGINARY OUTPUT" || key == "MAGNITUDE-PHASE OUTPUT") {
        complex = true;
      } else if (starts_with(key, "EIGENVALUE")) {
        // "$EIGENVALUE =  8.2327765E+06  MODE =     1"
        const auto w = words(key);
        if (w.size() != 6 || w[1] != "=" || w[3] != "MODE" || w[4] != "=")
          refuse(line, "an $EIGENVALUE line that cannot be read (expected '$EIGENVALUE = <value> MODE = <n>')");
        const auto ev = parse_real(w[2]);
        const auto n = parse_integer(w[5]);
        if (!ev || !n)
          refuse(line, "an $EIGENVALUE line that cannot be read (expected '$EIGENVALUE = <value> MODE = <n>')");
        if (eigenvectors) {
          if (complex) refuse(line, "a complex eigenvector block; expected the real modes of SOL 103");
          if (modes.count(*n))
            refuse(line, fmt::format("mode {} a second time (several subcases?): punch one SOL 103 subcase", *n));
          mode = &modes[*n];
          mode->number = *n;
          mode->eigenvalue = *ev;
          mode->cycles = std::sqrt(std::max(*ev, 0.0)) / (2 * std::numbers::pi);
        }
      } else if (key == "EIGENVECTOR") {
        eigenvectors = true;
      } else if (key.find("EIGENVECTOR") != std::string::npos) {
        refuse(line, fmt::format("'${}': only the real eigenvectors of SOL 103 are read", key));
      } else {
        eigenvectors = false;  // another table: displacements, forces, ...
        mode = nullptr;
      }
      continue;
    }
    if (!eigenvectors) continue;
    const auto w = words(s);
    if (w.empty()) continue;
    if (!mode) refuse(line, "an eigenvector row before its $EIGENVALUE line");
    auto values = [&](std::size_t from, int at) {
      if (w.size() != from + 3) refuse(line, "an eigenvector row that cannot be read (three values expected)");
      for (int c = 0; c < 3; ++c) {
        const auto x = parse_real(w[from + c]);
        if (!x) refuse(line, fmt::format("mode {}: '{}' is no number", mode->number, w[from + c]));
        (*row)(at + c) = *x;
      }
    };
    if (w[0] == "-CONT-") {
      if (!row) continue;  // a scalar point's or an unexpected continuation
      values(1, 3);
      row = nullptr;
      continue;
    }
    if (w[0].find_first_not_of("0123456789") != std::string::npos || w.size() < 2)
      refuse(line, "an eigenvector row that cannot be read (grid id and type expected)");
    if (row) refuse(line, fmt::format("grid {}: its -CONT- row (R1 R2 R3) is missing", row_grid));
    if (w[1] != "G") continue;  // a scalar or extra point carries no shape
    const auto grid = parse_integer(w[0]);
    if (!grid) refuse(line, fmt::format("grid id '{}' cannot be read", w[0]));
    row = &mode->shapes[*grid];
    row->setZero();
    row_grid = *grid;
    values(2, 0);
  }
  if (row) refuse(line, fmt::format("grid {}: its -CONT- row (R1 R2 R3) is missing at the end of the file", row_grid));
  if (modes.empty()) throw InputError(Diagnostic{path, 0, "", "no $EIGENVECTOR block (a SOL 103 run's punch file expected)"});
  std::vector<Mode> out;
  for (auto& [n, m] : modes) out.push_back(std::move(m));
  return out;
}

}  // namespace kanegen::nastran
