// Model parameters as named constants of the emitted code: exact 0 and +-1
// fold into the expressions (so the sparsity of the model is visible to the
// generator); every other value becomes a symbol printed by name and emitted
// once as `inline constexpr double name = value;  // what [unit]`, grouped
// by the body (or "model") it belongs to.
#pragma once

#include <ginac/ginac.h>

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace kanegen::codegen {

/// The group of the constants fold() derives (emitted last, sorted by name).
inline constexpr const char* kDerivedGroup = "derived";

class Constants {
 public:
  GiNaC::ex value(double v, const std::string& name, const std::string& unit, const std::string& what);
  /// e with every subexpression made only of constants (and numbers) replaced
  /// by one derived constant `kNNN = value;  // = expression` (constant sums
  /// and products are evaluated here, not at run time). Sums and products that
  /// mix constants and state keep one derived constant for their constant part.
  GiNaC::ex fold(const GiNaC::ex& e);
  /// Declarations of one group, in creation order.
  std::string emit(const std::string& group, const std::string& indent) const;
  /// A constant derived from the constant symbol `like` and named after it ("<like>_<suffix>", in its group):
  /// a quantity that every body has (a turn's double-angle terms), so that its role is the same for every
  /// body, unlike fold()'s hashed names and normalized signs. `like` must be a constant symbol.
  GiNaC::ex companion(const GiNaC::ex& like, const std::string& suffix, double v, const std::string& what);
  /// The value of an expression made of constants and numbers only (nullopt otherwise).
  std::optional<double> numeric_value(const GiNaC::ex& e) const;
  /// Groups in order of first use.
  std::vector<std::string> groups() const;
  /// Every constant's name (to keep temporaries from shadowing one).
  std::set<std::string> names() const;
  /// What a constant is, without naming its body: a model constant's name less its group's prefix
  /// ("link3_R_PJ_yy" -> "R_PJ_yy"), a derived one's expression in such roles, operands sorted. Two bodies'
  /// corresponding constants have one role (outlined_code.hpp orders kernels' operands by it).
  std::string role(const std::string& name) const;

  std::string group;  ///< group of the constants created next (set by the passes)

 private:
  struct Entry {
    double value;
    std::string unit, what, group;
    GiNaC::symbol sym;
    GiNaC::ex derived_from;  ///< a derived constant's expression (else 0)
  };
  std::string role_of(const GiNaC::ex& e) const;
  bool is_constant(const GiNaC::ex& e) const;
  double evaluate(const GiNaC::ex& e) const;
  GiNaC::ex derived(const GiNaC::ex& e);
  GiNaC::ex derived_unsigned(const GiNaC::ex& e);
  std::map<std::string, Entry> by_name_;
  std::vector<std::string> order_;
  std::map<GiNaC::ex, GiNaC::ex, GiNaC::ex_is_less> derived_;  ///< folded expression -> its constant
  GiNaC::exmap values_;                                         ///< constant symbol -> value

};

}  // namespace kanegen::codegen
