#include "codegen/program.hpp"

#include <fmt/format.h>

namespace kanegen::codegen {

using namespace GiNaC;

static bool trivial(const ex& e) {
  if (is_a<numeric>(e) || is_a<symbol>(e)) return true;
  if (is_a<mul>(e) && e.nops() == 2) {  // number * symbol: no temporary worth it
    const ex &a = e.op(0), &b = e.op(1);
    return (is_a<symbol>(a) && is_a<numeric>(b)) || (is_a<numeric>(a) && is_a<symbol>(b));
  }
  return false;
}

ex Program::let(const ex& e_in, const std::string& name) {
  const ex e = fold ? fold(e_in) : e_in;
  if (trivial(e)) return e;
  auto it = cse_.find(e);
  if (it != cse_.end()) return it->second;
  std::string n;
  if (name.empty()) {
    n = fmt::format("t{}", unnamed_);
  } else {
    n = name;
    for (int k = 2; names_.count(n); ++k) n = fmt::format("{}_{}", name, k);
  }
  // tNNN counts every temporary, named or not, so that adding a name to one
  // quantity does not renumber the others.
  ++unnamed_;
  names_.insert(n);
  symbol s(n);
  temps_.push_back({s, e, {}});
  cse_.emplace(e, s);
  return s;
}

void Program::assign(const std::string& lhs, const ex& e) { stmts_.push_back({lhs, "", fold ? fold(e) : e}); }

void Program::statement(const std::string& text, const ex& dep) { stmts_.push_back({"", text, dep}); }

void Program::section(const std::string& title) { temps_.push_back({symbol(), ex(0), title}); }

void Program::prelude(const std::string& text, const std::vector<std::string>& defines) {
  for (const auto& p : preludes_)
    if (p.text == text) return;
  preludes_.push_back({text, defines});
}

static void collect_symbols(const ex& e, std::set<std::string>& names) {
  if (is_a<symbol>(e)) {
    names.insert(ex_to<symbol>(e).get_name());
    return;
  }
  for (std::size_t i = 0; i < e.nops(); ++i) collect_symbols(e.op(i), names);
}

std::string Program::emit(const std::string& indent, OpCount& ops) const {
  // Liveness: walk temporaries backwards from the statements' needs.
  std::set<std::string> needed;
  for (const Stmt& s : stmts_) collect_symbols(s.value, needed);
  std::vector<bool> live(temps_.size(), false);
  for (std::size_t k = temps_.size(); k-- > 0;) {
    if (temps_[k].section.empty() && needed.count(temps_[k].sym.get_name())) {
      live[k] = true;
      collect_symbols(temps_[k].value, needed);
    }
  }
  std::string out;
  for (const Prelude& p : preludes_) {
    bool used = false;
    for (const auto& d : p.defines) used = used || needed.count(d);
    if (used) out += indent + p.text + "\n";
  }
  const std::string* pending = nullptr;  // a section marker not yet printed
  for (std::size_t k = 0; k < temps_.size(); ++k) {
    if (!temps_[k].section.empty()) {
      pending = &temps_[k].section;
      continue;
    }
    if (!live[k]) continue;
    if (pending) {
      out += fmt::format("{}// ---- {}\n", indent, *pending);
      pending = nullptr;
    }
    out += fmt::format("{}const T {} = {};\n", indent, temps_[k].sym.get_name(), print_cpp(temps_[k].value, ops));
  }
  for (const Stmt& s : stmts_) {
    if (s.lhs.empty())
      out += indent + s.text + "\n";
    else
      out += fmt::format("{}{} = {};\n", indent, s.lhs, print_cpp(s.value, ops));
  }
  return out;
}

}  // namespace kanegen::codegen
