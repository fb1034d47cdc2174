#include "fea/nastran_f06.hpp"

#include <fmt/format.h>

#include <fstream>
#include <sstream>

#include "fea/nastran_cards.hpp"
#include "model/diagnostics.hpp"

namespace kanegen::nastran {

namespace {

/// The line with its spaces removed (NASTRAN spaces out its headings: "R E A L   E I G E N V A L U E S").
std::string squeezed(const std::string& s) {
  std::string out;
  for (char c : s)
    if (c != ' ') out += c;
  return out;
}

}  // namespace

std::vector<Mode> read_f06_modes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(Diagnostic{path, 0, "", "cannot read the f06 file"});
  std::vector<std::string> lines;
  for (std::string s; std::getline(in, s);) {
    if (!s.empty() && s.back() == '\r') s.pop_back();
    lines.push_back(s);
  }
  auto refuse = [&](std::size_t k, const std::string& why) {
    throw InputError(Diagnostic{path, static_cast<int>(k) + 1, "", why});
  };
  std::map<int, Mode> modes;
  bool table = false;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    const std::string sq = squeezed(lines[k]);
    if (sq.find("COMPLEXEIGENVALUE") != std::string::npos)
      refuse(k, "a complex eigenvalue solution; expected the real modes of SOL 103");
    if (sq.find("REALEIGENVALUES") != std::string::npos) {
      table = true;
      // rows: MODE NO., EXTRACTION ORDER, EIGENVALUE, RADIANS, CYCLES, GENERALIZED MASS, GENERALIZED STIFFNESS
      for (std::size_t r = k + 1; r < lines.size(); ++r) {
        const auto w = words(lines[r]);
        if (w.empty()) continue;
        if (w[0] == "MODE" || w[0] == "NO.") continue;
        if (w.size() != 7 || w[0].find_first_not_of("0123456789") != std::string::npos) {
          k = r - 1;
          break;
        }
        Mode m;
        const auto number = parse_integer(w[0]);
        if (!number) refuse(r, fmt::format("mode number '{}' cannot be read", w[0]));
        m.number = *number;
        const auto ev = parse_real(w[2]), cy = parse_real(w[4]), gm = parse_real(w[5]);
        if (!ev || !cy || !gm) refuse(r, "an eigenvalue row that cannot be read");
        m.eigenvalue = *ev, m.cycles = *cy, m.generalized_mass = *gm;
        modes[m.number] = m;
      }
      continue;
    }
    const auto at = sq.find("REALEIGENVECTORNO.");
    if (at == std::string::npos) continue;
    const std::string tail = sq.substr(at + std::string("REALEIGENVECTORNO.").size());
    const auto parsed = parse_integer(tail.substr(0, tail.find_first_not_of("0123456789")));
    if (!parsed) refuse(k, "an eigenvector heading without a mode number that can be read");
    const int number = *parsed;
    Mode& m = modes[number];
    m.number = number;
    // rows after the "POINT ID. TYPE T1 ..." heading: id, type (G), six values; a page ends the block
    std::size_t r = k + 1;
    for (; r < lines.size(); ++r) {
      const auto w = words(lines[r]);
      if (w.empty()) continue;
      if (w[0] == "POINT") continue;
      if (w.size() != 8 || w[0].find_first_not_of("0123456789") != std::string::npos) break;
      if (w[1] != "G") continue;  // scalar points carry no shape
      Eigen::Matrix<double, 6, 1> v;
      for (int c = 0; c < 6; ++c) {
        const auto x = parse_real(w[2 + c]);
        if (!x) refuse(r, fmt::format("eigenvector {}: '{}' is no number", number, w[2 + c]));
        v(c) = *x;
      }
      const auto grid = parse_integer(w[0]);
      if (!grid) refuse(r, fmt::format("eigenvector {}: grid id '{}' cannot be read", number, w[0]));
      m.shapes[*grid] = v;
    }
    k = r - 1;
  }
  if (!table) throw InputError(Diagnostic{path, 0, "", "no REAL EIGENVALUES table (a SOL 103 run's f06 expected)"});
  std::vector<Mode> out;
  for (auto& [n, m] : modes) out.push_back(std::move(m));
  return out;
}

std::optional<F06Weight> read_f06_weight(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(Diagnostic{path, 0, "", "cannot read the f06 file"});
  std::vector<std::string> lines;
  for (std::string s; std::getline(in, s);) lines.push_back(s);
  for (std::size_t k = 0; k < lines.size(); ++k) {
    if (squeezed(lines[k]).find("GRIDPOINTWEIGHTGENERATOR") == std::string::npos) continue;
    F06Weight w;
    int row = 0;
    for (std::size_t r = k + 1; r < lines.size() && r < k + 12 && row < 6; ++r) {
      const std::string& s = lines[r];
      if (const auto p = s.find("REFERENCE POINT ="); p != std::string::npos) {
        const auto ws = words(s.substr(p + 17));
        const auto ref = ws.empty() ? std::nullopt : parse_integer(ws.front());
        if (!ref)
          throw InputError(Diagnostic{path, static_cast<int>(r) + 1, "", "a weight generator reference point that cannot be read"});
        w.reference_point = *ref;
        continue;
      }
      auto w6 = words(s);
      if (w6.size() != 8 || w6.front() != "*" || w6.back() != "*") continue;  // "* m11 ... m16 *"
      for (int c = 0; c < 6; ++c) {
        const auto x = parse_real(w6[1 + c]);
        if (!x) throw InputError(Diagnostic{path, static_cast<int>(r) + 1, "", "a weight generator row that cannot be read"});
        w.MO(row, c) = *x;
      }
      ++row;
    }
    if (row == 6) return w;
  }
  return std::nullopt;
}

}  // namespace kanegen::nastran
