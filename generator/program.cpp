#include "program.hpp"

#include <fmt/format.h>

#include <set>
#include <stdexcept>
#include <unordered_map>

namespace kanegen::gen {

using namespace GiNaC;

static bool trivial(const ex& e) {
  if (is_a<numeric>(e) || is_a<symbol>(e)) return true;
  if (is_a<mul>(e) && e.nops() == 2) {  // number * symbol: no temporary worth it
    const ex &a = e.op(0), &b = e.op(1);
    return (is_a<symbol>(a) && is_a<numeric>(b)) || (is_a<numeric>(a) && is_a<symbol>(b));
  }
  return false;
}

ex Program::let(const ex& e) {
  if (trivial(e)) return e;
  auto it = cse_.find(e);
  if (it != cse_.end()) return it->second;
  symbol s(fmt::format("t{}", temps_.size()));
  temps_.push_back({s, e});
  cse_.emplace(e, s);
  return s;
}

void Program::assign(const std::string& lhs, const ex& e) { stmts_.push_back({lhs, "", e}); }

void Program::statement(const std::string& text, const ex& dep) { stmts_.push_back({"", text, dep}); }

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
    if (needed.count(temps_[k].sym.get_name())) {
      live[k] = true;
      collect_symbols(temps_[k].value, needed);
    }
  }
  std::string out;
  for (std::size_t k = 0; k < temps_.size(); ++k) {
    if (!live[k]) continue;
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

// ---- printer ---------------------------------------------------------------

static std::string print_number(const numeric& n) {
  if (n.is_integer() && abs(n) < numeric(1L << 52)) return fmt::format("{}.0", n.to_long());
  if (n.is_rational()) return fmt::format("{:.17g}", n.to_double());
  if (n.is_real()) return fmt::format("{:.17g}", n.to_double());
  throw std::runtime_error("code printer: complex number");
}

static std::string print_rec(const ex& e, OpCount& ops, int prec);

// Precedence levels: 0 sum, 1 product, 2 atom.
static std::string paren(const std::string& s, bool p) { return p ? "(" + s + ")" : s; }

static std::string print_power_pos(const ex& base, long n, OpCount& ops) {
  const std::string b = print_rec(base, ops, 2);
  std::string s = b;
  for (long i = 1; i < n; ++i) s += "*" + b;
  ops.mul += n - 1;
  return s;
}

static std::string print_rec(const ex& e, OpCount& ops, int prec) {
  if (is_a<numeric>(e)) {
    const numeric& n = ex_to<numeric>(e);
    std::string s = print_number(n);
    return n.is_negative() ? paren(s, prec > 0) : s;
  }
  if (is_a<symbol>(e)) return ex_to<symbol>(e).get_name();
  if (is_a<add>(e)) {
    std::string s;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      const ex& t = e.op(i);
      // print "a - b" for negative terms
      bool neg = false;
      ex term = t;
      if (is_a<numeric>(t) && ex_to<numeric>(t).is_negative()) {
        neg = true;
        term = -t;
      } else if (is_a<mul>(t)) {
        const ex c = t.op(t.nops() - 1);
        if (is_a<numeric>(c) && ex_to<numeric>(c).is_negative()) {
          neg = true;
          term = -t;
        }
      }
      const std::string ts = print_rec(term, ops, neg ? 1 : 0);
      if (i == 0)
        s = neg ? "-" + paren(ts, is_a<add>(term)) : ts;
      else {
        s += neg ? " - " + ts : " + " + ts;
        ops.add += 1;
      }
      if (i == 0 && neg) ops.add += 0;
    }
    return paren(s, prec > 0);
  }
  if (is_a<mul>(e)) {
    std::vector<std::string> num, den;
    numeric coeff = 1;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      const ex& f = e.op(i);
      if (is_a<numeric>(f)) {
        coeff *= ex_to<numeric>(f);
      } else if (is_a<power>(f) && is_a<numeric>(f.op(1)) && ex_to<numeric>(f.op(1)).is_integer() &&
                 ex_to<numeric>(f.op(1)).is_negative()) {
        const long n = -ex_to<numeric>(f.op(1)).to_long();
        den.push_back(print_power_pos(f.op(0), n, ops));
      } else {
        num.push_back(print_rec(f, ops, 1));
      }
    }
    std::string s;
    const bool neg = coeff.is_negative();
    if (neg) coeff = -coeff;
    if (coeff != 1 || num.empty()) {
      // rational coefficient 1/k with no numerator factor -> divide
      if (coeff.is_rational() && !coeff.is_integer() && coeff.numer() == 1 && !num.empty()) {
        den.insert(den.begin(), print_number(coeff.denom()));
      } else {
        num.insert(num.begin(), print_number(coeff));
      }
    }
    for (std::size_t i = 0; i < num.size(); ++i) {
      if (i) {
        s += "*";
        ops.mul += 1;
      }
      s += num[i];
    }
    if (!den.empty()) {
      std::string d;
      for (std::size_t i = 0; i < den.size(); ++i) {
        if (i) {
          d += "*";
          ops.mul += 1;
        }
        d += den[i];
      }
      s += "/" + paren(d, den.size() > 1);
      ops.div += 1;
    }
    if (neg) return paren("-" + s, prec > 0);
    return paren(s, prec > 1 && !den.empty());
  }
  if (is_a<power>(e)) {
    const ex& b = e.op(0);
    const ex& x = e.op(1);
    if (is_a<numeric>(x)) {
      const numeric& n = ex_to<numeric>(x);
      if (n.is_integer()) {
        const long k = n.to_long();
        if (k > 0) return paren(print_power_pos(b, k, ops), prec > 1);
        ops.div += 1;
        return paren("1.0/" + paren(print_power_pos(b, -k, ops), -k > 1), prec > 0);
      }
      if (n == numeric(1, 2)) {
        ops.func += 1;
        return "sqrt(" + print_rec(b, ops, 0) + ")";
      }
      if (n == numeric(-1, 2)) {
        ops.func += 1;
        ops.div += 1;
        return paren("1.0/sqrt(" + print_rec(b, ops, 0) + ")", prec > 0);
      }
    }
    throw std::runtime_error(fmt::format("code printer: unsupported power {}", ex_to<basic>(e).class_name()));
  }
  if (is_a<function>(e)) {
    const std::string name = ex_to<function>(e).get_name();
    if (name == "sin" || name == "cos") {
      ops.func += 1;
      return name + "(" + print_rec(e.op(0), ops, 0) + ")";
    }
    throw std::runtime_error("code printer: unsupported function " + name);
  }
  throw std::runtime_error(std::string("code printer: unsupported expression of class ") +
                           ex_to<basic>(e).class_name());
}

std::string print_cpp(const ex& e, OpCount& ops) { return print_rec(e, ops, 0); }

}  // namespace kanegen::gen
