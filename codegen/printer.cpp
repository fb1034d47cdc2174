#include "codegen/printer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

namespace kanegen::codegen {

using namespace GiNaC;

// ---- printer ---------------------------------------------------------------
// Canonical text: GiNaC orders terms and factors (and picks the sign of a
// sum inside a product) by hash values that depend on memory addresses, so the
// printer sorts terms and factors by their text and writes every sum that is
// a factor with its first term positive. Same model, same bytes, every run.

static std::string print_number(const numeric& n) {
  if (n.is_integer() && abs(n) < numeric(1L << 52)) return fmt::format("{}.0", n.to_long());
  if (n.is_real()) return fmt::format("{}", n.to_double());
  throw std::runtime_error("code printer: complex number");
}

static std::string paren(const std::string& s, bool p) { return p ? "(" + s + ")" : s; }

static std::string print_atom(const ex& e, OpCount& ops);
static std::string print_term(const ex& t, bool& neg, OpCount& ops);

/// Sums and products of at least this many operands are printed as balanced trees.
constexpr std::size_t kBalancedFrom = 4;

/// items[lo, hi) joined by `op` as a balanced binary tree, e.g. (a + b) + (c + d).
static std::string balanced(const std::vector<std::string>& items, std::size_t lo, std::size_t hi,
                            const char* op) {
  if (hi - lo == 1) return items[lo];
  const std::size_t mid = lo + (hi - lo + 1) / 2;
  return paren(balanced(items, lo, mid, op), mid - lo > 1) + op + paren(balanced(items, mid, hi, op), hi - mid > 1);
}

/// A sum, terms sorted by text; with `normalize`, negated if needed so that
/// its first term is positive (`flipped` tells the caller).
static std::string print_sum(const ex& e, bool normalize, bool& flipped, OpCount& ops) {
  std::vector<std::pair<std::string, bool>> terms;
  for (std::size_t i = 0; i < e.nops(); ++i) {
    bool neg = false;
    std::string t = print_term(e.op(i), neg, ops);
    terms.emplace_back(std::move(t), neg);
  }
  std::sort(terms.begin(), terms.end());
  flipped = normalize && terms.front().second;
  if (terms.size() >= kBalancedFrom) {
    // (sum of the positive terms) - (sum of the negative ones), each summed as
    // a balanced tree: the same number of additions, a dependency chain of
    // log2(n) instead of n - 1 (C++ may not reassociate them itself)
    std::vector<std::string> pos, neg;
    for (const auto& [text, n] : terms) (n != flipped ? neg : pos).push_back(text);
    ops.add += static_cast<long>(terms.size()) - 1;
    if (pos.empty()) return "-(" + balanced(neg, 0, neg.size(), " + ") + ")";
    const std::string p = balanced(pos, 0, pos.size(), " + ");
    if (neg.empty()) return p;
    return paren(p, pos.size() > 1) + " - " + paren(balanced(neg, 0, neg.size(), " + "), neg.size() > 1);
  }
  std::string s;
  for (std::size_t i = 0; i < terms.size(); ++i) {
    const bool neg = terms[i].second != flipped;
    if (i == 0)
      s = neg ? "-" + terms[i].first : terms[i].first;
    else {
      s += (neg ? " - " : " + ") + terms[i].first;
      ops.add += 1;
    }
  }
  return s;
}

/// base^n for n > 0 as a product; `neg` set when the base was a sum whose
/// sign was normalized and n is odd.
static std::string print_positive_power(const ex& base, long n, bool& neg, OpCount& ops) {
  std::string b;
  if (is_a<add>(base)) {
    bool flipped = false;
    b = "(" + print_sum(base, true, flipped, ops) + ")";
    neg = flipped && (n % 2 == 1);
  } else {
    b = print_atom(base, ops);
  }
  std::string s = b;
  for (long i = 1; i < n; ++i) s += "*" + b;
  ops.mul += n - 1;
  return s;
}

/// A term of a sum or a whole product: magnitude text and its sign.
static std::string print_term(const ex& t, bool& neg, OpCount& ops) {
  neg = false;
  if (is_a<numeric>(t)) {
    const numeric& n = ex_to<numeric>(t);
    neg = n.is_negative();
    return print_number(neg ? -n : n);
  }
  if (!is_a<mul>(t)) {
    if (is_a<add>(t)) {
      bool flipped = false;
      const std::string s = "(" + print_sum(t, true, flipped, ops) + ")";
      neg = flipped;
      return s;
    }
    if (is_a<power>(t) && is_a<numeric>(t.op(1)) && ex_to<numeric>(t.op(1)).is_integer()) {
      const long k = ex_to<numeric>(t.op(1)).to_long();
      if (k > 0) return print_positive_power(t.op(0), k, neg, ops);
      const std::string d = print_positive_power(t.op(0), -k, neg, ops);
      ops.div += 1;
      return "1.0/" + paren(d, -k > 1 || d.find('*') != std::string::npos);
    }
    return print_atom(t, ops);
  }
  std::vector<std::string> num, den;
  numeric coeff = 1;
  for (std::size_t i = 0; i < t.nops(); ++i) {
    const ex& f = t.op(i);
    bool fneg = false;
    if (is_a<numeric>(f)) {
      coeff *= ex_to<numeric>(f);
    } else if (is_a<power>(f) && is_a<numeric>(f.op(1)) && ex_to<numeric>(f.op(1)).is_integer()) {
      const long k = ex_to<numeric>(f.op(1)).to_long();
      if (k > 0)
        num.push_back(print_positive_power(f.op(0), k, fneg, ops));
      else
        den.push_back(print_positive_power(f.op(0), -k, fneg, ops));
    } else if (is_a<add>(f)) {
      bool flipped = false;
      num.push_back("(" + print_sum(f, true, flipped, ops) + ")");
      fneg = flipped;
    } else {
      num.push_back(print_atom(f, ops));
    }
    if (fneg) neg = !neg;
  }
  if (coeff.is_negative()) {
    neg = !neg;
    coeff = -coeff;
  }
  std::sort(num.begin(), num.end());
  std::sort(den.begin(), den.end());
  if (coeff != 1 || num.empty()) {
    if (coeff.is_rational() && !coeff.is_integer() && coeff.numer() == 1 && !num.empty())
      den.insert(den.begin(), print_number(coeff.denom()));
    else
      num.insert(num.begin(), print_number(coeff));
  }
  std::string s;
  if (num.size() >= kBalancedFrom) {
    s = balanced(num, 0, num.size(), "*");
    ops.mul += static_cast<long>(num.size()) - 1;
  } else {
    for (std::size_t i = 0; i < num.size(); ++i) {
      if (i) {
        s += "*";
        ops.mul += 1;
      }
      s += num[i];
    }
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
    s += "/" + paren(d, den.size() > 1 || d.find('*') != std::string::npos);
    ops.div += 1;
  }
  return s;
}

/// Symbols, functions and half-integer powers: never need parentheses.
static std::string print_atom(const ex& e, OpCount& ops) {
  if (is_a<symbol>(e)) return ex_to<symbol>(e).get_name();
  if (is_a<numeric>(e)) {
    bool neg = false;
    const std::string s = print_term(e, neg, ops);
    return neg ? "(-" + s + ")" : s;
  }
  if (is_a<power>(e) && is_a<numeric>(e.op(1))) {
    const numeric& n = ex_to<numeric>(e.op(1));
    if (n == numeric(1, 2)) {
      ops.func += 1;
      return "sqrt(" + print_cpp(e.op(0), ops) + ")";
    }
    if (n == numeric(-1, 2)) {
      ops.func += 1;
      ops.div += 1;
      return "(1.0/sqrt(" + print_cpp(e.op(0), ops) + "))";
    }
    if (n.is_integer()) {
      bool neg = false;
      const std::string s = print_term(e, neg, ops);
      return "(" + std::string(neg ? "-" : "") + s + ")";
    }
    throw std::runtime_error("code printer: unsupported power");
  }
  if (is_a<function>(e)) {
    const std::string name = ex_to<function>(e).get_name();
    if (name == "sin" || name == "cos") {
      ops.func += 1;
      return name + "(" + print_cpp(e.op(0), ops) + ")";
    }
    throw std::runtime_error("code printer: unsupported function " + name);
  }
  if (is_a<add>(e) || is_a<mul>(e)) {
    bool neg = false;
    const std::string s = print_term(e, neg, ops);
    return "(" + std::string(neg ? "-" : "") + s + ")";
  }
  throw std::runtime_error(std::string("code printer: unsupported expression of class ") +
                           ex_to<basic>(e).class_name());
}

std::string print_cpp(const ex& e, OpCount& ops) {
  if (is_a<add>(e)) {
    bool flipped = false;
    return print_sum(e, false, flipped, ops);
  }
  bool neg = false;
  const std::string s = print_term(e, neg, ops);
  return neg ? "-" + s : s;
}

}  // namespace kanegen::codegen
