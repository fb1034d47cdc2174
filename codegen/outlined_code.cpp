#include "codegen/outlined_code.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <sstream>
#include <tuple>

namespace kanegen::codegen {

using namespace GiNaC;

namespace {

/// The body a section's title names ("body link3: outward pass" -> "link3"), or "".
std::string body_of(const std::string& title) {
  if (title.rfind("body ", 0) != 0) return {};
  const auto colon = title.find(':');
  return colon == std::string::npos ? std::string() : title.substr(5, colon - 5);
}

/// Symbols replaced by name (the program's symbols are distinct objects from any made here, so a map keyed
/// by name covers temporaries and runtime symbols alike).
struct Rename : map_function {
  const std::map<std::string, ex>& by_name;
  explicit Rename(const std::map<std::string, ex>& m) : by_name(m) {}
  ex operator()(const ex& e) override {
    if (is_a<symbol>(e)) {
      auto it = by_name.find(ex_to<symbol>(e).get_name());
      return it != by_name.end() ? it->second : e;
    }
    return e.map(*this);
  }
};

struct Group {
  std::string body;
  std::vector<int> temps;  ///< indices into the listing's temporaries, in order
};

/// a < b with runs of digits compared as numbers ("t999" < "t1000").
bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
      const std::string da = a.substr(i, ie - i), db = b.substr(j, je - j);
      if (da.size() != db.size()) return da.size() < db.size();
      if (da != db) return da < db;
      i = ie, j = je;
      continue;
    }
    if (a[i] != b[j]) return a[i] < b[j];
    ++i, ++j;
  }
  return a.size() - i < b.size() - j;
}

/// One group's canonical form: its locals numbered in order, its inputs and constants numbered in a
/// traversal that orders operands by shape (numbers, locals, "an input", "a constant"), not by name.
class Canonical {
 public:
  /// `local`: the group's temporaries by name -> index; `role`: an external's role ("C..." a constant, else
  /// an input).
  Canonical(const std::map<std::string, int>& local, const std::map<std::string, std::string>& role)
      : local_(local), role_(role) {}

  void visit(const ex& e) {
    if (is_a<symbol>(e)) {
      const std::string& n = ex_to<symbol>(e).get_name();
      if (local_.count(n)) return;
      auto& order = role_.at(n)[0] == 'C' ? constant_order : input_order;
      if (std::find(order.begin(), order.end(), n) == order.end()) order.push_back(n);
      return;
    }
    // operands by shape; equal shapes by their printed text (canonical, so the header's bytes do not depend on
    // GiNaC's address-based order), numbers in it compared as numbers: temporaries are numbered in the order
    // the generator makes them, the same for every body, and t999 must come before t1000 as t99 before t100
    std::vector<std::tuple<std::string, std::string, std::size_t>> operands;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      OpCount unused;
      std::string text = print_cpp(e.op(i), unused);  // canonical, signs of sums normalized; its own sign dropped
      if (!text.empty() && text[0] == '-') text.erase(0, 1);
      operands.emplace_back(shape(e.op(i)), std::move(text), i);
    }
    if (is_a<add>(e) || is_a<mul>(e))
      std::sort(operands.begin(), operands.end(), [](const auto& a, const auto& b) {
        if (std::get<0>(a) != std::get<0>(b)) return std::get<0>(a) < std::get<0>(b);
        return natural_less(std::get<1>(a), std::get<1>(b));
      });
    for (const auto& o : operands) visit(e.op(std::get<2>(o)));
  }

  std::vector<std::string> input_order, constant_order;

 private:
  /// The shape, blind to signs: GiNaC keeps a sum inside a product with the sign that makes its hash-first
  /// term positive, so -(p - q) r in one run is (q - p) r in the next; a numeric factor's sign and a factor
  /// -1 are left out (a -x is shaped as x).
  std::string shape(const ex& e) const {
    if (is_a<symbol>(e)) {
      const std::string& n = ex_to<symbol>(e).get_name();
      if (auto it = local_.find(n); it != local_.end()) return fmt::format("a{}", it->second);
      return role_.at(n);
    }
    if (is_a<numeric>(e)) {
      std::ostringstream s;
      s << abs(ex_to<numeric>(e));
      return s.str();
    }
    std::vector<std::string> operands;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      if (is_a<mul>(e) && is_a<numeric>(e.op(i)) && abs(ex_to<numeric>(e.op(i))) == 1) continue;
      operands.push_back(shape(e.op(i)));
    }
    if (is_a<mul>(e) && operands.size() == 1) return operands[0];
    if (is_a<add>(e) || is_a<mul>(e)) std::sort(operands.begin(), operands.end());
    const std::string head = is_a<add>(e)        ? "+"
                             : is_a<mul>(e)      ? "*"
                             : is_a<power>(e)    ? "^"
                             : is_a<function>(e) ? ex_to<function>(e).get_name()
                                                 : ex_to<basic>(e).class_name();
    return head + "(" + fmt::format("{}", fmt::join(operands, ",")) + ")";
  }

  const std::map<std::string, int>& local_;
  const std::map<std::string, std::string>& role_;
};

}  // namespace

OutlinedBody outline(const Program& program, const std::string& name, const Constants& model_constants,
                     const std::string& indent, OpCount& ops) {
  const std::set<std::string> constants = model_constants.names();
  const Program::Listing listing = program.listing(indent);
  const auto& temps = listing.temps;
  const int nt = static_cast<int>(temps.size());
  std::map<std::string, int> index_of;  // temporary -> its index in the listing
  for (int k = 0; k < nt; ++k) index_of[temps[k].sym.get_name()] = k;
  std::vector<std::set<std::string>> reads(nt);
  for (int k = 0; k < nt; ++k) collect_symbols(temps[k].value, reads[k]);

  // 1. groups: the sections, a body's later section fused into its last group when every temporary it reads
  // is computed by then
  std::vector<Group> groups;
  std::vector<int> group_of(nt, -1);
  for (int k = 0; k < nt;) {
    int end = k + 1;
    while (end < nt && temps[end].section.empty()) ++end;
    const std::string body = body_of(temps[k].section);
    int target = -1;
    if (!body.empty()) {
      int last = -1;
      for (int g = static_cast<int>(groups.size()) - 1; g >= 0 && last < 0; --g)
        if (groups[g].body == body) last = g;
      bool ready = last >= 0;
      for (int i = k; i < end && ready; ++i)
        for (const std::string& n : reads[i]) {
          auto it = index_of.find(n);
          if (it != index_of.end() && (it->second < k || it->second >= end) && group_of[it->second] > last) {
            ready = false;
            break;
          }
        }
      if (ready) target = last;
    }
    if (target < 0) {
      target = static_cast<int>(groups.size());
      groups.push_back({body, {}});
    }
    for (int i = k; i < end; ++i) {
      groups[target].temps.push_back(i);
      group_of[i] = target;
    }
    k = end;
  }

  // 2. the workspace: every temporary read outside its group, and every runtime value a group reads (the state,
  // inputs, time, the preludes' values), copied in first
  std::map<std::string, int> slot;
  std::vector<std::string> runtime;  // runtime values, in order of first use
  auto slot_of = [&](const std::string& n) {
    auto it = slot.find(n);
    if (it != slot.end()) return it->second;
    const int s = static_cast<int>(slot.size());
    slot.emplace(n, s);
    return s;
  };
  for (const Group& g : groups)
    for (int k : g.temps)
      for (const std::string& n : reads[k]) {
        auto it = index_of.find(n);
        if (it != index_of.end()) {
          if (group_of[it->second] != group_of[k]) slot_of(n);
        } else if (!constants.count(n) && !slot.count(n)) {
          slot_of(n);
          runtime.push_back(n);
        }
      }
  std::vector<std::set<std::string>> statement_reads(listing.statements.size());
  for (std::size_t i = 0; i < listing.statements.size(); ++i) {
    collect_symbols(listing.statements[i].value, statement_reads[i]);
    for (const std::string& n : statement_reads[i])
      if (index_of.count(n)) slot_of(n);
  }

  // 3. each external's role: a constant's (Constants::role), another group's temporary by its place in that
  // group and that group's section (its body's name left out, "self" when it is this group's body), a
  // runtime value by its array
  std::vector<int> place(nt, 0);
  for (const Group& g : groups)
    for (std::size_t i = 0; i < g.temps.size(); ++i) place[g.temps[i]] = static_cast<int>(i);
  auto section_kind = [&](int g) {
    const std::string& title = temps[groups[g].temps.front()].section;
    const auto colon = title.find(':');
    return colon == std::string::npos ? title : title.substr(colon);
  };

  // 4. each group's canonical text; equal texts share a kernel
  OutlinedBody out;
  std::map<std::string, int> kernel_of_text;
  std::string calls;
  for (const Group& g : groups) {
    std::map<std::string, int> local;
    for (std::size_t i = 0; i < g.temps.size(); ++i) local[temps[g.temps[i]].sym.get_name()] = static_cast<int>(i);
    std::map<std::string, std::string> role;
    for (int k : g.temps)
      for (const std::string& n : reads[k]) {
        if (local.count(n) || role.count(n)) continue;
        if (constants.count(n)) {
          role[n] = "C" + model_constants.role(n);
        } else if (auto it = index_of.find(n); it != index_of.end()) {
          const int dg = group_of[it->second];
          role[n] = fmt::format("X{}{}{}", groups[dg].body == g.body ? "self" : "other", section_kind(dg),
                                place[it->second]);
        } else {
          role[n] = "X" + n.substr(0, n.find('['));
        }
      }
    Canonical canon(local, role);
    for (int k : g.temps) canon.visit(temps[k].value);
    std::vector<std::string> x;  // the x table: input slots, then output slots
    std::string text;
    for (std::size_t i = 0; i < canon.input_order.size(); ++i) {
      const std::string& n = canon.input_order[i];
      x.push_back(std::to_string(slot.at(n)));
      text += fmt::format("{}const T X{} = w[x[{}]];\n", indent, i, i);
    }
    for (std::size_t i = 0; i < canon.constant_order.size(); ++i)
      text += fmt::format("{}const double C{} = c[{}];\n", indent, i, i);
    // the substitution: locals a<i>, inputs X<i>, constants C<i>
    std::map<std::string, ex> by_name;
    for (const auto& [n, i] : local) by_name[n] = symbol(fmt::format("a{}", i));
    for (std::size_t i = 0; i < canon.input_order.size(); ++i) by_name[canon.input_order[i]] = symbol(fmt::format("X{}", i));
    for (std::size_t i = 0; i < canon.constant_order.size(); ++i)
      by_name[canon.constant_order[i]] = symbol(fmt::format("C{}", i));
    Rename sub(by_name);
    OpCount group_ops;
    for (std::size_t i = 0; i < g.temps.size(); ++i)
      text += fmt::format("{}const T a{} = {};\n", indent, i, print_cpp(sub(temps[g.temps[i]].value), group_ops));
    ops += group_ops;
    for (std::size_t i = 0; i < g.temps.size(); ++i) {
      const std::string& n = temps[g.temps[i]].sym.get_name();
      if (auto it = slot.find(n); it != slot.end()) {
        text += fmt::format("{}w[x[{}]] = a{};\n", indent, x.size(), i);
        x.push_back(std::to_string(it->second));
      }
    }
    auto [it, added] = kernel_of_text.emplace(text, static_cast<int>(out.kernels.size()));
    if (added) {
      out.kernels.push_back(text);
      out.kernel_ops += group_ops;
    }
    // the call's tables at namespace scope with internal linkage: a function-local static of a template is a
    // GNU unique symbol, which the dynamic loader binds across libraries (two variants of one model's code
    // loaded in one process would read each other's tables)
    const std::string section = temps[g.temps.front()].section;
    const int call = out.calls++;
    out.tables += fmt::format("// {}\nstatic constexpr int {}_x{}[] = {{{}}};\n",
                              section.empty() ? "(the function's first values)" : section, name, call, fmt::join(x, ", "));
    if (canon.constant_order.empty()) {
      calls += fmt::format("{}{}_kernel{}(w, {}_x{}, static_cast<const double*>(nullptr));\n", indent, name, it->second,
                           name, call);
    } else {
      out.tables += fmt::format("static constexpr double {}_c{}[] = {{{}}};\n", name, call,
                                fmt::join(canon.constant_order, ", "));
      calls += fmt::format("{}{}_kernel{}(w, {}_x{}, {}_c{});\n", indent, name, it->second, name, call, name, call);
    }
  }

  // 5. the function's body
  out.workspace = static_cast<int>(slot.size());
  std::string& m = out.main;
  m = listing.preludes;
  m += fmt::format("{}T w[{}];\n", indent, std::max(1, out.workspace));
  for (const std::string& n : runtime) m += fmt::format("{}w[{}] = {};\n", indent, slot.at(n), n);
  m += calls;
  std::map<std::string, ex> from_workspace;
  for (const auto& [n, s] : slot)
    if (index_of.count(n)) from_workspace[n] = symbol(fmt::format("w[{}]", s));
  Rename load(from_workspace);
  std::set<std::string> loaded;
  for (std::size_t i = 0; i < listing.statements.size(); ++i) {
    const Program::Statement& s = listing.statements[i];
    if (!s.lhs.empty()) {
      m += fmt::format("{}{} = {};\n", indent, s.lhs, print_cpp(load(s.value), ops));
      continue;
    }
    for (const std::string& n : statement_reads[i])
      if (index_of.count(n) && loaded.insert(n).second) m += fmt::format("{}const T {} = w[{}];\n", indent, n, slot.at(n));
    m += indent + s.text + "\n";
  }
  return out;
}

}  // namespace kanegen::codegen
