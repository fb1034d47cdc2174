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

  // 2. the workspace's entries: every temporary read outside its group or by the statements, and every runtime
  // value a group reads (the state, inputs, time, the preludes' values; copied in first). Each entry lives in the
  // region of a group: a temporary in its own group's, a runtime value in that of the first group reading it.
  const int ng = static_cast<int>(groups.size());
  std::map<std::string, int> owner;  // entry -> the group whose region holds it
  std::vector<std::string> runtime;  // runtime values, in order of first use
  for (int g = 0; g < ng; ++g)
    for (int k : groups[g].temps)
      for (const std::string& n : reads[k]) {
        auto it = index_of.find(n);
        if (it != index_of.end()) {
          if (group_of[it->second] != g) owner.emplace(n, group_of[it->second]);
        } else if (!constants.count(n) && owner.emplace(n, g).second) {
          runtime.push_back(n);
        }
      }
  std::vector<std::set<std::string>> statement_reads(listing.statements.size());
  for (std::size_t i = 0; i < listing.statements.size(); ++i) {
    collect_symbols(listing.statements[i].value, statement_reads[i]);
    for (const std::string& n : statement_reads[i])
      if (auto it = index_of.find(n); it != index_of.end()) owner.emplace(n, group_of[it->second]);
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

  // 4. each group's canonical text; equal texts share a kernel. A call's entries: its inputs (in the kernel's
  // order), then the outputs it keeps in the workspace.
  struct Call {
    int kernel = 0;
    std::vector<std::string> entries;
    std::vector<int> outputs;  ///< the locals (a<i>) stored, one per output entry
    std::vector<std::string> constants;
    std::string section;
  };
  struct Kernel {
    int inputs = 0, constants = 0;
    std::string locals;  ///< the lines `const T a<i> = ...;`
    std::vector<int> calls;
  };
  OutlinedBody out;
  std::vector<Call> call(ng);
  std::vector<Kernel> kernels;
  std::map<std::string, int> kernel_of_text;
  for (int gi = 0; gi < ng; ++gi) {
    const Group& g = groups[gi];
    std::map<std::string, int> local;
    for (std::size_t i = 0; i < g.temps.size(); ++i) local[temps[g.temps[i]].sym.get_name()] = static_cast<int>(i);
    std::map<std::string, std::string> role;
    for (int k : g.temps)
      for (const std::string& n : reads[k]) {
        if (local.count(n) || role.count(n)) continue;
        if (constants.count(n)) {
          role[n] = fmt::format("C{}", model_constants.role(n));
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
    // the substitution: locals a<i>, inputs X<i>, constants C<i>
    std::map<std::string, ex> by_name;
    for (const auto& [n, i] : local) by_name[n] = symbol(fmt::format("a{}", i));
    for (std::size_t i = 0; i < canon.input_order.size(); ++i) by_name[canon.input_order[i]] = symbol(fmt::format("X{}", i));
    for (std::size_t i = 0; i < canon.constant_order.size(); ++i)
      by_name[canon.constant_order[i]] = symbol(fmt::format("C{}", i));
    Rename sub(by_name);
    OpCount group_ops;
    std::string locals;
    for (std::size_t i = 0; i < g.temps.size(); ++i)
      locals += fmt::format("{}const T a{} = {};\n", indent, i, print_cpp(sub(temps[g.temps[i]].value), group_ops));
    ops += group_ops;
    Call& c = call[gi];
    c.entries = canon.input_order;
    for (std::size_t i = 0; i < g.temps.size(); ++i)
      if (const std::string& n = temps[g.temps[i]].sym.get_name(); owner.count(n)) {
        c.entries.push_back(n);
        c.outputs.push_back(static_cast<int>(i));
      }
    c.constants = canon.constant_order;
    c.section = temps[g.temps.front()].section;
    // the key: the text with every entry read and written through the table
    std::string key = fmt::format("{} inputs, {} constants\n{}", canon.input_order.size(), canon.constant_order.size(), locals);
    for (int o : c.outputs) key += fmt::format("w <- a{}\n", o);
    auto [it, added] = kernel_of_text.emplace(key, static_cast<int>(kernels.size()));
    if (added) {
      kernels.push_back({static_cast<int>(canon.input_order.size()), static_cast<int>(canon.constant_order.size()),
                         std::move(locals), {}});
      out.kernel_ops += group_ops;
    }
    c.kernel = it->second;
    kernels[it->second].calls.push_back(gi);
  }

  // 5. the layout (issue 38): each body's entries in a region of its own, the regions of one stride, each call
  // given its region's start. An entry a kernel reads or writes at the same offset from every call's start is
  // addressed by that constant in the kernel's text; the rest through the call's table. Offsets are classes of
  // entries: a kernel's entry at one place joins the classes of its calls' entries at that place (when they lie
  // at one distance of regions from their calls and no two of them share a region), and every class gets one
  // offset within its regions, so a chain's like bodies put like values at like offsets.
  std::map<std::string, int> region_index;  // a group's body (or "#g" for a group of no body) -> its region
  std::vector<int> region(ng);
  for (int g = 0; g < ng; ++g) {
    const std::string key = groups[g].body.empty() ? fmt::format("#{}", g) : groups[g].body;
    region[g] = region_index.emplace(key, static_cast<int>(region_index.size())).first->second;
  }
  const int nr = static_cast<int>(region_index.size());
  std::vector<std::string> entry_name;  // entries by number, in order of first use
  std::map<std::string, int> entry;
  auto add_entry = [&](const std::string& n) {
    if (entry.emplace(n, static_cast<int>(entry_name.size())).second) entry_name.push_back(n);
  };
  for (const std::string& n : runtime) add_entry(n);
  for (const Call& c : call)
    for (const std::string& n : c.entries) add_entry(n);
  for (const auto& [n, g] : owner) add_entry(n);
  const int ne = static_cast<int>(entry_name.size());
  std::vector<int> entry_region(ne);
  for (int e = 0; e < ne; ++e) entry_region[e] = region[owner.at(entry_name[e])];
  // classes: union-find, each class's entries by region
  std::vector<int> parent(ne);
  std::vector<std::map<int, int>> members(ne);  // root -> region -> entry
  for (int e = 0; e < ne; ++e) parent[e] = e, members[e][entry_region[e]] = e;
  auto find = [&](int e) {
    while (parent[e] != e) e = parent[e] = parent[parent[e]];
    return e;
  };
  std::vector<int> by_calls(kernels.size());
  for (std::size_t k = 0; k < kernels.size(); ++k) by_calls[k] = static_cast<int>(k);
  std::stable_sort(by_calls.begin(), by_calls.end(),
                   [&](int a, int b) { return kernels[a].calls.size() > kernels[b].calls.size(); });
  for (int k : by_calls) {
    const Kernel& K = kernels[k];
    if (K.calls.size() < 2) continue;
    for (std::size_t p = 0; p < call[K.calls[0]].entries.size(); ++p) {
      std::set<int> roots;
      bool one_distance = true;
      const int distance = entry_region[entry.at(call[K.calls[0]].entries[p])] - region[K.calls[0]];
      for (int g : K.calls) {
        const int e = entry.at(call[g].entries[p]);
        one_distance = one_distance && entry_region[e] - region[g] == distance;
        roots.insert(find(e));
      }
      if (!one_distance) continue;
      std::map<int, int> merged;
      bool apart = true;
      for (int r : roots)
        for (const auto& [reg, e] : members[r]) apart = apart && merged.emplace(reg, e).second;
      if (!apart) continue;
      const int root = *roots.begin();
      for (int r : roots) parent[r] = root;
      members[root] = std::move(merged);
    }
  }
  // each class an offset free in all its regions, the widest classes first
  std::vector<int> roots;
  for (int e = 0; e < ne; ++e)
    if (find(e) == e) roots.push_back(e);
  std::stable_sort(roots.begin(), roots.end(), [&](int a, int b) { return members[a].size() > members[b].size(); });
  std::vector<std::vector<bool>> used(nr);
  std::vector<int> offset_of_root(ne, -1);
  int stride = 1;
  for (int r : roots) {
    auto taken = [&](int o) {
      for (const auto& [reg, e] : members[r])
        if (o < static_cast<int>(used[reg].size()) && used[reg][o]) return true;
      return false;
    };
    int o = 0;
    while (taken(o)) ++o;
    offset_of_root[r] = o;
    for (const auto& [reg, e] : members[r]) {
      if (static_cast<int>(used[reg].size()) <= o) used[reg].resize(o + 1, false);
      used[reg][o] = true;
    }
    stride = std::max(stride, o + 1);
  }
  // the regions' starts: one stride while at most a third of the workspace is gaps; else each region as long
  // as it needs (one body with far more values than the others, e.g. a flexible body's nodes among rigid
  // links); else each region's values packed without gaps. The kernels of like bodies next to a region of
  // another length, or whose values moved, read through their tables.
  const long budget = ne + ne / 2 + 64;
  long lengths = 0;
  for (int r = 0; r < nr; ++r) lengths += static_cast<long>(used[r].size());
  const bool one_stride = static_cast<long>(nr) * stride <= budget, gapless = !one_stride && lengths > budget;
  std::vector<std::vector<int>> at(nr);  // region -> offset -> place in the region
  std::vector<int> region_start(nr + 1, 0);
  for (int r = 0; r < nr; ++r) {
    int n = 0;
    for (bool u : used[r]) at[r].push_back(u && gapless ? n++ : static_cast<int>(at[r].size()));
    const int length = one_stride ? stride : gapless ? n : static_cast<int>(used[r].size());
    region_start[r + 1] = region_start[r] + length;
  }
  std::map<std::string, int> slot;
  for (int e = 0; e < ne; ++e)
    slot[entry_name[e]] = region_start[entry_region[e]] + at[entry_region[e]][offset_of_root[find(e)]];
  auto base = [&](int g) { return region_start[region[g]]; };

  // 6. the kernels' texts: an entry at one offset from every call's start by that offset, the others through
  // the call's table x
  std::vector<std::vector<int>> table_place(kernels.size());  // per kernel, per entry: its place in x, or -1
  for (std::size_t k = 0; k < kernels.size(); ++k) {
    const Kernel& K = kernels[k];
    const Call& first = call[K.calls[0]];
    std::vector<int>& tp = table_place[k];
    int next = 0;
    std::string text;
    for (std::size_t p = 0; p < first.entries.size(); ++p) {
      const int d = slot.at(first.entries[p]) - base(K.calls[0]);
      bool fixed = true;
      for (int g : K.calls) fixed = fixed && slot.at(call[g].entries[p]) - base(g) == d;
      tp.push_back(fixed ? -1 : next++);
      const std::string at = fixed ? fmt::format("w[{}]", d) : fmt::format("w[x[{}]]", tp.back());
      if (static_cast<int>(p) < K.inputs) text += fmt::format("{}const T X{} = {};\n", indent, p, at);
    }
    if (next == 0) text += indent + "(void)x;\n";
    for (int i = 0; i < K.constants; ++i) text += fmt::format("{}const double C{} = c[{}];\n", indent, i, i);
    text += K.locals;
    for (std::size_t j = 0; j < first.outputs.size(); ++j) {
      const std::size_t p = K.inputs + j;
      const std::string at = tp[p] < 0 ? fmt::format("w[{}]", slot.at(first.entries[p]) - base(K.calls[0]))
                                       : fmt::format("w[x[{}]]", tp[p]);
      text += fmt::format("{}{} = a{};\n", indent, at, first.outputs[j]);
    }
    out.kernels.push_back(std::move(text));
  }

  // 7. the calls and their tables, at namespace scope with internal linkage: a function-local static of a template
  // is a GNU unique symbol, which the dynamic loader binds across libraries (two variants of one model's code
  // loaded in one process would read each other's tables)
  std::string calls;
  for (int g = 0; g < ng; ++g) {
    const Call& c = call[g];
    const int n = out.calls++;
    std::vector<int> x;
    for (std::size_t p = 0; p < c.entries.size(); ++p)
      if (table_place[c.kernel][p] >= 0) x.push_back(slot.at(c.entries[p]) - base(g));
    out.tables += fmt::format("// {}\n", c.section.empty() ? "(the function's first values)" : c.section);
    std::string x_arg = "static_cast<const int*>(nullptr)", c_arg = "static_cast<const double*>(nullptr)";
    if (!x.empty()) {
      out.tables += fmt::format("static constexpr int {}_x{}[] = {{{}}};\n", name, n, fmt::join(x, ", "));
      x_arg = fmt::format("{}_x{}", name, n);
    }
    if (!c.constants.empty()) {
      out.tables += fmt::format("static constexpr double {}_c{}[] = {{{}}};\n", name, n, fmt::join(c.constants, ", "));
      c_arg = fmt::format("{}_c{}", name, n);
    }
    calls += fmt::format("{}{}_kernel{}(w + {}, {}, {});\n", indent, name, c.kernel, base(g), x_arg, c_arg);
  }

  // 8. the function's body
  out.workspace = region_start[nr];
  out.workspace_values = ne;
  std::string& m = out.main;
  m = listing.preludes;
  ops += listing.prelude_ops;
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
