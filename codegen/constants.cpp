#include "codegen/constants.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace kanegen::codegen {

GiNaC::ex Constants::value(double v, const std::string& name, const std::string& unit, const std::string& what) {
  if (v == 0.0) return 0;
  if (v == 1.0) return 1;
  if (v == -1.0) return -1;
  // The same quantity may take two values, e.g. a body's mass with and
  // without the fixed children merged into it: the second gets a suffix.
  std::string key = name;
  for (int k = 2;; ++k) {
    auto it = by_name_.find(key);
    if (it == by_name_.end()) break;
    if (it->second.value == v) return it->second.sym;
    key = fmt::format("{}_{}", name, k);
  }
  Entry e{v, unit, what, group, GiNaC::symbol(key)};
  const GiNaC::ex s = e.sym;
  by_name_.emplace(key, std::move(e));
  order_.push_back(key);
  return s;
}

std::vector<std::string> Constants::groups() const {
  std::vector<std::string> g;
  for (const auto& n : order_) {
    const std::string& gr = by_name_.at(n).group;
    if (std::find(g.begin(), g.end(), gr) == g.end()) g.push_back(gr);
  }
  return g;
}

std::set<std::string> Constants::names() const {
  std::set<std::string> s;
  for (const auto& [n, e] : by_name_) s.insert(n);
  return s;
}

std::string Constants::emit(const std::string& grp, const std::string& indent) const {
  std::string out;
  for (const auto& n : order_) {
    const Entry& e = by_name_.at(n);
    if (e.group != grp) continue;
    std::string comment = e.what;
    if (!e.unit.empty()) comment += " [" + e.unit + "]";
    out += fmt::format("{}inline constexpr double {} = {};  // {}\n", indent, n, e.value, comment);
  }
  return out;
}

}  // namespace kanegen::codegen
