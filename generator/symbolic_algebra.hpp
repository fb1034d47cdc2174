// Small symbolic vectors and matrices over GiNaC expressions whose every
// computed entry is bound to a temporary of a Program (program.hpp), and the
// registry of named model constants.
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

#include "program.hpp"

namespace kanegen::gen {

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

/// Operations that bind their results in a Program.
class Alg {
 public:
  explicit Alg(Program& p) : P(p) {}
  Program& P;

  ex let(const ex& e) { return P.let(e); }
  SV3 add(const SV3& a, const SV3& b) { return map2(a, b, [](const ex& x, const ex& y) { return x + y; }); }
  SV3 sub(const SV3& a, const SV3& b) { return map2(a, b, [](const ex& x, const ex& y) { return x - y; }); }
  SV3 scale(const ex& s, const SV3& a) {
    SV3 r;
    for (int i = 0; i < 3; ++i) r[i] = let(s * a[i]);
    return r;
  }
  SV3 cross(const SV3& a, const SV3& b) {
    SV3 r;
    r[0] = let(a[1] * b[2] - a[2] * b[1]);
    r[1] = let(a[2] * b[0] - a[0] * b[2]);
    r[2] = let(a[0] * b[1] - a[1] * b[0]);
    return r;
  }
  ex dot(const SV3& a, const SV3& b) { return let(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]); }
  SV3 mul(const SM3& A, const SV3& x) {
    SV3 r;
    for (int i = 0; i < 3; ++i) r[i] = let(A(i, 0) * x[0] + A(i, 1) * x[1] + A(i, 2) * x[2]);
    return r;
  }
  SV3 mul_t(const SM3& A, const SV3& x) { return mul(A.transpose(), x); }
  SM3 mul(const SM3& A, const SM3& B) {
    SM3 r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r(i, j) = let(A(i, 0) * B(0, j) + A(i, 1) * B(1, j) + A(i, 2) * B(2, j));
    return r;
  }
  static SM3 skew(const SV3& a) {
    SM3 s;
    s(0, 1) = -a[2], s(0, 2) = a[1];
    s(1, 0) = a[2], s(1, 2) = -a[0];
    s(2, 0) = -a[1], s(2, 1) = a[0];
    return s;
  }

 private:
  template <class F>
  SV3 map2(const SV3& a, const SV3& b, F f) {
    SV3 r;
    for (int i = 0; i < 3; ++i) r[i] = let(f(a[i], b[i]));
    return r;
  }
};

/// Model parameters as named constants: exact 0 and +-1 fold into the
/// expressions; every other value becomes a symbol printed by name and
/// emitted once as `inline constexpr double name = value; // unit, what`.
class Constants {
 public:
  ex value(double v, const std::string& name, const std::string& unit, const std::string& what);
  /// Declarations grouped by the body (or "model") each constant belongs to.
  std::string emit(const std::string& group, const std::string& indent) const;
  std::vector<std::string> groups() const;
  double numeric_value(const std::string& name) const;

 private:
  struct Entry {
    double value;
    std::string unit, what, group;
    GiNaC::symbol sym;
  };
  std::map<std::string, Entry> by_name_;
  std::vector<std::string> order_;

 public:
  std::string group;  ///< group of the constants created next (set by the builder)
};

}  // namespace kanegen::gen
