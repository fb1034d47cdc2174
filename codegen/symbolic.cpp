#include "codegen/symbolic.hpp"

#include <fmt/format.h>

namespace kanegen::codegen {

static const char* kAxis[3] = {"x", "y", "z"};

ex dot(const std::vector<ex>& a, const std::vector<ex>& b) {
  ex s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

std::string Alg::component(const std::string& name, int i) { return name.empty() ? name : name + "_" + kAxis[i]; }

std::string Alg::entry(const std::string& name, int r, int c) {
  return name.empty() ? name : fmt::format("{}_{}{}", name, kAxis[r], kAxis[c]);
}

SV3 Alg::let(const SV3& a, const std::string& name) {
  SV3 r;
  for (int i = 0; i < 3; ++i) r[i] = let(a[i], component(name, i));
  return r;
}

SV3 Alg::add(const SV3& a, const SV3& b, const std::string& name) {
  SV3 r;
  for (int i = 0; i < 3; ++i) r[i] = let(a[i] + b[i], component(name, i));
  return r;
}

SV3 Alg::sub(const SV3& a, const SV3& b, const std::string& name) {
  SV3 r;
  for (int i = 0; i < 3; ++i) r[i] = let(a[i] - b[i], component(name, i));
  return r;
}

SV3 Alg::scale(const ex& s, const SV3& a, const std::string& name) {
  SV3 r;
  for (int i = 0; i < 3; ++i) r[i] = let(s * a[i], component(name, i));
  return r;
}

SV3 Alg::cross(const SV3& a, const SV3& b, const std::string& name) {
  SV3 r;
  r[0] = let(a[1] * b[2] - a[2] * b[1], component(name, 0));
  r[1] = let(a[2] * b[0] - a[0] * b[2], component(name, 1));
  r[2] = let(a[0] * b[1] - a[1] * b[0], component(name, 2));
  return r;
}

ex Alg::dot(const SV3& a, const SV3& b, const std::string& name) {
  return let(a[0] * b[0] + a[1] * b[1] + a[2] * b[2], name);
}

SV3 Alg::mul(const SM3& A, const SV3& x, const std::string& name) {
  SV3 r;
  for (int i = 0; i < 3; ++i) r[i] = let(A(i, 0) * x[0] + A(i, 1) * x[1] + A(i, 2) * x[2], component(name, i));
  return r;
}

SM3 Alg::mul(const SM3& A, const SM3& B, const std::string& name) {
  SM3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r(i, j) = let(A(i, 0) * B(0, j) + A(i, 1) * B(1, j) + A(i, 2) * B(2, j), entry(name, i, j));
  return r;
}

SM3 Alg::skew(const SV3& a) {
  SM3 s;
  s(0, 1) = -a[2], s(0, 2) = a[1];
  s(1, 0) = a[2], s(1, 2) = -a[0];
  s(2, 0) = -a[1], s(2, 1) = a[0];
  return s;
}

StateSymbols::StateSymbols(const Model& m) {
  for (int i = 0; i < m.nq; ++i) q.push_back(GiNaC::symbol(fmt::format("q[{}]", i)));
  for (int i = 0; i < m.nu; ++i) {
    u.push_back(GiNaC::symbol(fmt::format("u[{}]", i)));
    tau.push_back(GiNaC::symbol(fmt::format("tau[{}]", i)));
    udot.push_back(GiNaC::symbol(fmt::format("udot_in[{}]", i)));
  }
  for (int i = 0; i < m.nw; ++i) inputs.push_back(GiNaC::symbol(fmt::format("inputs[{}]", i)));
  for (std::size_t i = 0; i < m.parameters.size(); ++i) params.push_back(GiNaC::symbol(fmt::format("prm[{}]", i)));
}

}  // namespace kanegen::codegen
