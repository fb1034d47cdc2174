// Small symbolic vectors and matrices over GiNaC expressions, and the
// operations on them that bind every computed entry to a temporary of a
// Program (program.hpp): the vocabulary the symbolic Kane passes are written in.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "codegen/program.hpp"
#include "model/model.hpp"

namespace kanegen::codegen {

struct SV3 {
  std::array<ex, 3> v{0, 0, 0};
  ex& operator[](int i) { return v[i]; }
  const ex& operator[](int i) const { return v[i]; }
};

struct SM3 {
  std::array<std::array<ex, 3>, 3> m{{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}};
  ex& operator()(int r, int c) { return m[r][c]; }
  const ex& operator()(int r, int c) const { return m[r][c]; }
  static SM3 identity() {
    SM3 I;
    for (int i = 0; i < 3; ++i) I(i, i) = 1;
    return I;
  }
  SM3 transpose() const {
    SM3 t;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) t(r, c) = m[c][r];
    return t;
  }
};

/// Dense symbolic matrix (row-major).
struct SMat {
  int rows = 0, cols = 0;
  std::vector<ex> a;
  SMat() = default;
  SMat(int r, int c) : rows(r), cols(c), a(static_cast<std::size_t>(r) * c, ex(0)) {}
  ex& operator()(int r, int c) { return a[static_cast<std::size_t>(r) * cols + c]; }
  const ex& operator()(int r, int c) const { return a[static_cast<std::size_t>(r) * cols + c]; }
};

/// Sum a_i b_i of two equally long expression vectors (not bound).
ex dot(const std::vector<ex>& a, const std::vector<ex>& b);

/// Operations that bind their results in a Program. A `name` (e.g.
/// "ant2_w_B") names the temporaries of a new result after what it is:
/// name_x, name_y, name_z for vectors, name for scalars.
class Alg {
 public:
  explicit Alg(Program& p) : P(p) {}
  Program& P;

  ex let(const ex& e, const std::string& name = {}) { return P.let(e, name); }
  SV3 let(const SV3& a, const std::string& name = {});
  SV3 add(const SV3& a, const SV3& b, const std::string& name = {});
  SV3 sub(const SV3& a, const SV3& b, const std::string& name = {});
  SV3 scale(const ex& s, const SV3& a, const std::string& name = {});
  SV3 cross(const SV3& a, const SV3& b, const std::string& name = {});
  ex dot(const SV3& a, const SV3& b, const std::string& name = {});
  SV3 mul(const SM3& A, const SV3& x, const std::string& name = {});
  SV3 mul_t(const SM3& A, const SV3& x, const std::string& name = {}) { return mul(A.transpose(), x, name); }
  SM3 mul(const SM3& A, const SM3& B, const std::string& name = {});
  static SM3 skew(const SV3& a);
  /// Name of component i of a vector called `name` ("" stays "").
  static std::string component(const std::string& name, int i);
  /// Name of entry (r, c) of a matrix called `name`.
  static std::string entry(const std::string& name, int r, int c);
};

/// Symbols of the state arrays, printed as q[i], u[i], tau[i], udot_in[i].
struct StateSymbols {
  std::vector<ex> q, u, tau, udot;
  std::vector<ex> inputs;  ///< the named inputs w (model.nw)
  std::vector<ex> params;  ///< the runtime parameters prm (model.parameters)
  explicit StateSymbols(const Model& m);
};

}  // namespace kanegen::codegen
