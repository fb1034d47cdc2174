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

bool Program::reads_temporary(const ex& e) const {
  std::set<std::string> syms;
  collect_symbols(e, syms);
  for (const std::string& n : syms)
    if (names_.count(n)) return true;
  return false;
}

std::pair<ex, ex> Program::sincos(const ex& angle_in) {
  const ex angle = fold ? fold(angle_in) : angle_in;
  if (reads_temporary(angle)) throw std::logic_error("Program::sincos: the angle reads a temporary");
  auto it = angle_index_.find(angle);
  if (it == angle_index_.end()) {
    const std::size_t i = angles_.size();
    angles_.push_back({angle, symbol(fmt::format("angle_s[{}]", i)), symbol(fmt::format("angle_c[{}]", i))});
    it = angle_index_.emplace(angle, i).first;
  }
  const Angle& a = angles_[it->second];
  return {a.s, a.c};
}

void collect_symbols(const ex& e, std::set<std::string>& names) {
  if (is_a<symbol>(e)) {
    names.insert(ex_to<symbol>(e).get_name());
    return;
  }
  for (std::size_t i = 0; i < e.nops(); ++i) collect_symbols(e.op(i), names);
}

std::vector<bool> Program::liveness(std::set<std::string>& needed) const {
  // walk temporaries backwards from the statements' needs
  for (const Stmt& s : stmts_) collect_symbols(s.value, needed);
  std::vector<bool> live(temps_.size(), false);
  for (std::size_t k = temps_.size(); k-- > 0;) {
    if (temps_[k].section.empty() && needed.count(temps_[k].sym.get_name())) {
      live[k] = true;
      collect_symbols(temps_[k].value, needed);
    }
  }
  return live;
}

/// The angles' batch: `kanegen_sincos_n` of the arguments into angle_s and angle_c, local arrays or (`w_base` not
/// negative) the workspace from w[w_base] (the first part of a function in parts); `alias`: only name the
/// workspace's arrays (the later parts).
static std::string angle_batch(const std::string& indent, int n, const std::string& list, int w_base = -1,
                               bool alias = false) {
  std::string out = fmt::format("{}// ---- joint angles' sin and cos, in one batch (joint_sincos.inc)\n", indent);
  if (w_base >= 0) {
    out += fmt::format("{}{}T* angle_s = w + {};\n", indent, alias ? "const " : "", w_base);
    out += fmt::format("{}{}T* angle_c = w + {};\n", indent, alias ? "const " : "", w_base + n);
    if (alias) return out + fmt::format("{}(void)angle_s; (void)angle_c;\n", indent);
  } else {
    out += fmt::format("{}T angle_s[{}], angle_c[{}];\n", indent, n, n);
  }
  out += fmt::format("{}const T angle_x[{}] = {{{}}};\n", indent, n, list);
  out += fmt::format("{}kanegen_sincos_n(angle_x, angle_s, angle_c, {});\n", indent, n);
  return out;
}

void Program::used_preludes(const std::set<std::string>& needed, const std::string& indent, Listing& out) const {
  bool angles = false;
  for (const Angle& a : angles_) angles = angles || needed.count(a.s.get_name()) || needed.count(a.c.get_name());
  std::set<std::string> all = needed;  // and what the angles read (a prescribed angle's prelude value)
  if (angles)
    for (const Angle& a : angles_) collect_symbols(a.angle, all);
  for (const Prelude& p : preludes_) {
    bool used = false;
    for (const auto& d : p.defines) used = used || all.count(d);
    if (used) out.plain_preludes += indent + p.text + "\n";
  }
  out.preludes = out.plain_preludes;
  if (!angles) return;
  // every angle, so that the symbols' indices hold
  out.angles = static_cast<int>(angles_.size());
  for (const Angle& a : angles_) out.angle_list += (out.angle_list.empty() ? "" : ", ") + print_cpp(a.angle, out.prelude_ops);
  out.prelude_ops.func += 2L * out.angles;
  out.preludes += angle_batch(indent, out.angles, out.angle_list);
}

std::string Program::emit(const std::string& indent, OpCount& ops) const {
  const Listing l = listing(indent);
  std::string out = l.preludes;
  ops += l.prelude_ops;
  for (const LiveTemp& t : l.temps) {
    if (!t.section.empty()) out += fmt::format("{}// ---- {}\n", indent, t.section);
    out += fmt::format("{}const T {} = {};\n", indent, t.sym.get_name(), print_cpp(t.value, ops));
  }
  for (const Statement& s : l.statements) {
    if (s.lhs.empty())
      out += indent + s.text + "\n";
    else
      out += fmt::format("{}{} = {};\n", indent, s.lhs, print_cpp(s.value, ops));
  }
  return out;
}

Program::Listing Program::listing(const std::string& indent) const {
  std::set<std::string> needed;
  const std::vector<bool> live = liveness(needed);
  Listing out;
  used_preludes(needed, indent, out);
  const std::string* pending = nullptr;
  for (std::size_t k = 0; k < temps_.size(); ++k) {
    if (!temps_[k].section.empty()) {
      pending = &temps_[k].section;
      continue;
    }
    if (!live[k]) continue;
    out.temps.push_back({temps_[k].sym, temps_[k].value, pending ? *pending : std::string()});
    pending = nullptr;
  }
  for (const Stmt& s : stmts_) out.statements.push_back({s.lhs, s.text, s.value});
  return out;
}

std::vector<std::pair<std::string, long>> Program::ops_by_pass() const {
  const Listing l = listing("");
  std::vector<std::pair<std::string, long>> out;
  auto add = [&](const std::string& pass, long ops) {
    for (auto& [p, n] : out)
      if (p == pass) {
        n += ops;
        return;
      }
    out.emplace_back(pass, ops);
  };
  if (l.prelude_ops.total()) add("joint angles' sin and cos", l.prelude_ops.total());
  std::string pass = "(first values)";
  for (const LiveTemp& t : l.temps) {
    if (!t.section.empty()) {
      const auto colon = t.section.find(": ");
      pass = t.section.rfind("body ", 0) == 0 && colon != std::string::npos ? t.section.substr(colon + 2) : t.section;
    }
    OpCount c;
    print_cpp(t.value, c);
    add(pass, c.total());
  }
  for (const Statement& st : l.statements) {
    if (st.lhs.empty()) continue;
    OpCount c;
    print_cpp(st.value, c);
    if (c.total()) add("outputs", c.total());
  }
  return out;
}

ChunkedBody Program::emit_chunked(const std::string& indent, OpCount& ops, long max_chunk_ops) const {
  const Listing listed = listing(indent);
  ops += listed.prelude_ops;  // the first part computes the angles' batch; the other preludes every part again
  // 1. the live temporaries in order, their text, cost and chunk
  struct Line {
    const LiveTemp* temp;       ///< a temporary, or nullptr for an output assignment
    const Statement* output;
    std::string text;
    int chunk;
  };
  std::vector<Line> lines;
  std::map<std::string, int> chunk_of;  // temporary -> chunk that defines it
  int chunk = 0;
  long in_chunk = 0;
  for (const LiveTemp& t : listed.temps) {
    OpCount c;
    std::string text = print_cpp(t.value, c);
    ops += c;
    if (in_chunk > 0 && in_chunk + c.total() > max_chunk_ops) ++chunk, in_chunk = 0;
    in_chunk += c.total();
    lines.push_back({&t, nullptr, std::move(text), chunk});
    chunk_of[t.sym.get_name()] = chunk;
  }
  // the outputs, in the same sequence of parts (the verbatim statements, which
  // may return, stay in the function itself)
  for (const Statement& st : listed.statements) {
    if (st.lhs.empty()) continue;
    OpCount c;
    std::string text = print_cpp(st.value, c);
    ops += c;
    if (in_chunk > 0 && in_chunk + c.total() + 1 > max_chunk_ops) ++chunk, in_chunk = 0;
    in_chunk += c.total() + 1;
    lines.push_back({nullptr, &st, std::move(text), chunk});
  }
  const int last = chunk + 1;  // the verbatim statements form the last part (the function itself)
  // 2. which temporaries cross a part boundary: they go through the workspace
  std::map<std::string, int> slot;
  std::vector<std::set<std::string>> loads(last + 1);  // per part: temporaries read from the workspace
  auto uses = [&](const ex& e, int part) {
    std::set<std::string> syms;
    collect_symbols(e, syms);
    for (const auto& n : syms) {
      auto it = chunk_of.find(n);
      if (it == chunk_of.end() || it->second == part) continue;
      slot.emplace(n, static_cast<int>(slot.size()));
      loads[part].insert(n);
    }
  };
  for (const Line& l : lines) uses(l.output ? l.output->value : l.temp->value, l.chunk);
  for (const Statement& s : listed.statements)
    if (s.lhs.empty()) uses(s.value, last);
  // 3. the parts
  ChunkedBody out;
  // the angles' batch once, in the first part, into the workspace after the parts' values; the later parts and
  // the function itself read it there
  const int batch_base = static_cast<int>(slot.size());
  out.parts.assign(last, listed.plain_preludes);
  std::string main = listed.plain_preludes;
  if (listed.angles > 0) {
    for (int p = 0; p < last; ++p)
      out.parts[p] += angle_batch(indent, listed.angles, listed.angle_list, batch_base, p > 0);
    main += angle_batch(indent, listed.angles, listed.angle_list, batch_base, true);
  }
  auto load_text = [&](int part) {
    std::string t;
    for (const auto& n : loads[part]) t += fmt::format("{}const T {} = w[{}];\n", indent, n, slot.at(n));
    return t;
  };
  for (int p = 0; p < last; ++p) out.parts[p] += load_text(p);
  main += load_text(last);
  for (const Line& l : lines) {
    std::string& dst = out.parts[l.chunk];
    if (l.output) {
      dst += fmt::format("{}{} = {};\n", indent, l.output->lhs, l.text);
      continue;
    }
    if (!l.temp->section.empty()) dst += fmt::format("{}// ---- {}\n", indent, l.temp->section);
    const std::string& n = l.temp->sym.get_name();
    dst += fmt::format("{}const T {} = {};\n", indent, n, l.text);
    if (auto it = slot.find(n); it != slot.end()) dst += fmt::format("{}w[{}] = {};\n", indent, it->second, n);
  }
  for (const Statement& s : listed.statements)
    if (s.lhs.empty()) main += indent + s.text + "\n";
  out.main = std::move(main);
  out.workspace = static_cast<int>(slot.size()) + 2 * listed.angles;
  return out;
}

}  // namespace kanegen::codegen
