// A straight-line program under construction: every non-trivial
// intermediate quantity of the symbolic formulation is bound to a temporary
// symbol by let(), with common-subexpression elimination (structurally equal
// expressions share one temporary). This keeps every expression small, so
// the emitted code grows with the number of operations the recursive
// formulation performs, not with the size of expanded closed forms.
#pragma once

#include <ginac/ginac.h>

#include <map>
#include <string>
#include <vector>

namespace kanegen::gen {

using GiNaC::ex;

struct OpCount {
  long add = 0, mul = 0, div = 0, func = 0;  // func: sqrt, sin, cos
  long total() const { return add + mul + div + func; }
  OpCount& operator+=(const OpCount& o) {
    add += o.add, mul += o.mul, div += o.div, func += o.func;
    return *this;
  }
};

class Program {
 public:
  /// Binds e to a temporary (reusing one for an equal expression); numbers,
  /// symbols and a number times a symbol are returned as they are.
  ex let(const ex& e);
  /// Records `lhs = e;` as an output statement (in order).
  void assign(const std::string& lhs, const ex& e);
  /// A plain statement emitted verbatim after the temporaries it needs
  /// (e.g. `if (D3 <= 0) return 4;`), depending on expression `dep`.
  void statement(const std::string& text, const ex& dep);

  /// C++ body: temporaries that some output needs (dead ones dropped), in
  /// order, as `const T tK = ...;`, then the outputs. Counts operations.
  std::string emit(const std::string& indent, OpCount& ops) const;

  std::size_t temporaries() const { return temps_.size(); }

 private:
  struct Temp {
    GiNaC::symbol sym;
    ex value;
  };
  std::vector<Temp> temps_;
  std::map<ex, ex, GiNaC::ex_is_less> cse_;
  struct Stmt {
    std::string lhs;  // empty for verbatim statements
    std::string text;
    ex value;
  };
  std::vector<Stmt> stmts_;
};

/// Prints an expression as C++ (integer powers as products, x^-1 as 1/x,
/// x^(1/2) as sqrt); throws std::runtime_error on anything else.
std::string print_cpp(const ex& e, OpCount& ops);

}  // namespace kanegen::gen
