// The expression printer of the emitter: a GiNaC expression as C++
// (integer powers as products, x^-1 as 1/x, x^(1/2) as sqrt), in a
// canonical text that does not depend on GiNaC's address-based term order,
// with the operations it costs counted. Anything else throws.
#pragma once

#include <ginac/ginac.h>

#include <string>

namespace kanegen::codegen {

struct OpCount {
  long add = 0, mul = 0, div = 0, func = 0;  // func: sqrt, sin, cos
  long total() const { return add + mul + div + func; }
  OpCount& operator+=(const OpCount& o) {
    add += o.add, mul += o.mul, div += o.div, func += o.func;
    return *this;
  }
};

/// Prints an expression as C++; throws std::runtime_error on anything it
/// cannot print exactly (complex numbers, non-half-integer powers, functions
/// other than sin, cos).
std::string print_cpp(const GiNaC::ex& e, OpCount& ops);

}  // namespace kanegen::codegen
