#include "codegen/constants.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "codegen/printer.hpp"

namespace kanegen::codegen {

namespace {

/// The double v as an exact GiNaC rational.
GiNaC::ex exact(double v) {
  int e = 0;
  const double m = std::frexp(v, &e);  // v = m 2^e, 0.5 <= |m| < 1
  const auto mantissa = static_cast<long long>(std::ldexp(m, 53));
  return GiNaC::numeric(static_cast<long>(mantissa)) * GiNaC::pow(GiNaC::numeric(2), e - 53);
}

}  // namespace

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
  values_[s] = exact(v);
  by_name_.emplace(key, std::move(e));
  order_.push_back(key);
  return s;
}

bool Constants::is_constant(const GiNaC::ex& e) const {
  if (GiNaC::is_a<GiNaC::numeric>(e)) return true;
  if (GiNaC::is_a<GiNaC::symbol>(e)) return values_.count(e) > 0;
  if (GiNaC::is_a<GiNaC::function>(e)) return false;  // sin, cos of constants: left to the compiler
  for (std::size_t i = 0; i < e.nops(); ++i)
    if (!is_constant(e.op(i))) return false;
  return true;
}

double Constants::evaluate(const GiNaC::ex& e) const {
  // exact rational arithmetic, rounded once: the value does not depend on the
  // order in which GiNaC keeps the terms
  const GiNaC::ex v = e.subs(values_);
  if (!GiNaC::is_a<GiNaC::numeric>(v) || !GiNaC::ex_to<GiNaC::numeric>(v).is_real())
    throw std::logic_error("constant folding: not a real number");
  return GiNaC::ex_to<GiNaC::numeric>(v).to_double();
}

GiNaC::ex Constants::companion(const GiNaC::ex& like, const std::string& suffix, double v, const std::string& what) {
  const auto it = by_name_.find(GiNaC::ex_to<GiNaC::symbol>(like).get_name());
  if (it == by_name_.end()) throw std::logic_error("constants: a companion of a symbol that is no constant");
  const std::string saved = group;
  group = it->second.group;
  const GiNaC::ex r = value(v, it->first + "_" + suffix, "", what);
  group = saved;
  return r;
}

std::optional<double> Constants::numeric_value(const GiNaC::ex& e) const {
  if (!is_constant(e)) return std::nullopt;
  return evaluate(e);
}

GiNaC::ex Constants::derived(const GiNaC::ex& e) {
  // GiNaC may hold the same quantity as -(a b) in one run and (-a) b in the
  // next (its term order follows hash values): a derived constant is free of
  // a numeric factor, and a sum is taken with the sign that makes it
  // positive, so both forms give the same constant
  // A product takes its sums (and their integer powers) with the sign that makes them positive:
  // -(a - b) c and (b - a) c are one constant.
  if (GiNaC::is_a<GiNaC::mul>(e)) {
    GiNaC::ex sign = 1, rest = 1;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      const GiNaC::ex f = e.op(i);
      if (GiNaC::is_a<GiNaC::numeric>(f)) {
        sign *= f;
      } else if (GiNaC::is_a<GiNaC::add>(f) && evaluate(f) < 0.0) {
        sign = -sign;
        rest *= -f;
      } else if (GiNaC::is_a<GiNaC::power>(f) && GiNaC::is_a<GiNaC::add>(f.op(0)) && f.op(1).info(GiNaC::info_flags::integer) &&
                 evaluate(f.op(0)) < 0.0) {
        if (f.op(1).info(GiNaC::info_flags::odd)) sign = -sign;
        rest *= GiNaC::pow(-f.op(0), f.op(1));
      } else {
        rest *= f;
      }
    }
    return sign * derived_unsigned(rest);
  }
  if (GiNaC::is_a<GiNaC::add>(e) && evaluate(e) < 0.0) return -derived_unsigned(-e);
  return derived_unsigned(e);
}

GiNaC::ex Constants::derived_unsigned(const GiNaC::ex& e) {
  if (GiNaC::is_a<GiNaC::numeric>(e) || GiNaC::is_a<GiNaC::symbol>(e)) return e;
  if (auto it = derived_.find(e); it != derived_.end()) return it->second;
  const double v = evaluate(e);
  GiNaC::ex r;
  if (v == 0.0 || v == 1.0 || v == -1.0) {
    r = GiNaC::numeric(static_cast<long>(v));
  } else {
    OpCount unused;
    std::string text = print_cpp(e, unused);
    // named by a hash of its (canonical) text, kept in one group sorted by
    // name: the same model gives the same bytes whatever order they arise in
    std::uint64_t h = 1469598103934665603ULL;  // FNV-1a
    for (const unsigned char ch : text) h = (h ^ ch) * 1099511628211ULL;
    if (text.size() > 100) text = text.substr(0, 97) + "...";
    const std::string saved = group;
    group = kDerivedGroup;
    r = value(v, fmt::format("k{:08x}", static_cast<std::uint32_t>(h ^ (h >> 32))), "", "= " + text);
    group = saved;
    if (GiNaC::is_a<GiNaC::symbol>(r)) {
      Entry& entry = by_name_.at(GiNaC::ex_to<GiNaC::symbol>(r).get_name());
      if (entry.derived_from.is_zero()) entry.derived_from = e;
    }

  }
  derived_.emplace(e, r);
  return r;
}

GiNaC::ex Constants::fold(const GiNaC::ex& e) {
  using namespace GiNaC;

  if (is_a<numeric>(e) || is_a<symbol>(e)) return e;
  if (is_constant(e)) return derived(e);
  if (is_a<add>(e) || is_a<mul>(e)) {
    const bool sum = is_a<add>(e);
    ex constant_part = sum ? ex(0) : ex(1), rest = sum ? ex(0) : ex(1);
    int constant_terms = 0;
    // operands in the order of their text (GiNaC's own order depends on
    // hash values), so that derived constants are created in the same order
    // every run
    std::vector<std::pair<std::string, ex>> ops;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      OpCount unused;
      ops.emplace_back(print_cpp(e.op(i), unused), e.op(i));
    }
    std::sort(ops.begin(), ops.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [text, op] : ops) {
      const ex t = fold(op);
      if (is_constant(t)) {
        constant_part = sum ? constant_part + t : constant_part * t;
        if (!is_a<numeric>(t)) ++constant_terms;
      } else {
        rest = sum ? rest + t : rest * t;
      }
    }
    // a lone constant symbol (times a number) stays as it is (derived() keeps it)
    const ex c = constant_terms > 0 ? derived(constant_part) : constant_part;
    return sum ? c + rest : c * rest;
  }
  if (is_a<power>(e)) return pow(fold(e.op(0)), e.op(1));
  if (is_a<function>(e)) {
    ex r = e;
    for (std::size_t i = 0; i < e.nops(); ++i) r = r.subs(e.op(i) == fold(e.op(i)));
    return r;
  }
  return e;
}

std::vector<std::string> Constants::groups() const {
  std::vector<std::string> g;
  bool derived = false;
  for (const auto& n : order_) {
    const std::string& gr = by_name_.at(n).group;
    if (gr == kDerivedGroup) derived = true;
    else if (std::find(g.begin(), g.end(), gr) == g.end()) g.push_back(gr);
  }
  if (derived) g.push_back(kDerivedGroup);  // last, whenever they arose
  return g;
}

std::set<std::string> Constants::names() const {
  std::set<std::string> s;
  for (const auto& [n, e] : by_name_) s.insert(n);
  return s;
}

std::string Constants::role(const std::string& name) const {
  auto it = by_name_.find(name);
  if (it == by_name_.end()) return name;
  const Entry& e = it->second;
  if (!e.derived_from.is_zero()) return "(" + role_of(e.derived_from) + ")";
  const std::string prefix = e.group + "_";
  return name.rfind(prefix, 0) == 0 ? name.substr(prefix.size()) : name;
}

std::string Constants::role_of(const GiNaC::ex& e) const {
  // blind to signs, as GiNaC may hold -(a - b) c as (b - a) c in another run (roles only order operands)
  if (GiNaC::is_a<GiNaC::symbol>(e)) return role(GiNaC::ex_to<GiNaC::symbol>(e).get_name());
  if (GiNaC::is_a<GiNaC::numeric>(e)) {
    OpCount unused;
    return print_cpp(GiNaC::abs(GiNaC::ex_to<GiNaC::numeric>(e)), unused);
  }
  std::vector<std::string> operands;
  for (std::size_t i = 0; i < e.nops(); ++i) {
    if (GiNaC::is_a<GiNaC::mul>(e) && GiNaC::is_a<GiNaC::numeric>(e.op(i)) &&
        GiNaC::abs(GiNaC::ex_to<GiNaC::numeric>(e.op(i))) == 1)
      continue;
    operands.push_back(role_of(e.op(i)));
  }
  if (GiNaC::is_a<GiNaC::mul>(e) && operands.size() == 1) return operands[0];
  const bool commutative = GiNaC::is_a<GiNaC::add>(e) || GiNaC::is_a<GiNaC::mul>(e);
  if (commutative) std::sort(operands.begin(), operands.end());
  const std::string head = GiNaC::is_a<GiNaC::add>(e) ? "+" : GiNaC::is_a<GiNaC::mul>(e) ? "*" : GiNaC::is_a<GiNaC::power>(e) ? "^" : "f";
  return head + "(" + fmt::format("{}", fmt::join(operands, ",")) + ")";
}

std::string Constants::emit(const std::string& grp, const std::string& indent) const {
  std::string out;
  std::vector<std::string> names = order_;
  if (grp == kDerivedGroup) std::sort(names.begin(), names.end());
  for (const auto& n : names) {
    const Entry& e = by_name_.at(n);
    if (e.group != grp) continue;
    std::string comment = e.what;
    if (!e.unit.empty()) comment += " [" + e.unit + "]";
    out += fmt::format("{}inline constexpr double {} = {};  // {}\n", indent, n, e.value, comment);
  }
  return out;
}

}  // namespace kanegen::codegen
