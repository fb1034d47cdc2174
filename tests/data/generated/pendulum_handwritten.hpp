// Hand-written stand-in for a generated model header (the shape the generator
// emits), used with pendulum_handwritten.entry.cpp and .manifest.json only by
// tests/engine/test_jit.cpp to test the JIT plumbing without the generator.
//
// Model (built programmatically in the test, see make_handwritten_pendulum()):
// one body "bob", revolute about y of N at the origin, mass m, com [L, 0, 0],
// I_c = diag(0, Iyy, 0), gravity [0, 0, -g], joint spring k (rest r0) and
// damper c; outputs: energy and momentum (NOT reactions: its table entry must
// be NULL). With theta the joint angle:
//   M = m L^2 + Iyy
//   F = m g L cos(theta) - k (theta - r0) - c u + tau
//   T = 1/2 M u^2,  V = -m g L sin(theta) + 1/2 k (theta - r0)^2
//   p_N = m L u (-sin, 0, -cos),  H_N = (0, M u, 0)
#pragma once

#include <cmath>

namespace kanegen_gen::pendulum_handwritten {

inline constexpr int nq = 1;
inline constexpr int nu = 1;
inline constexpr int nbodies = 1;

namespace p {
inline constexpr double m = 2.0, L = 0.75, Iyy = 0.1, g = 9.81, k = 0.5, c = 0.2, r0 = 0.1;
}

template <class T>
void qdot(const T* q, const T* u, T* qd) {
  (void)q;
  qd[0] = u[0];
}

template <class T>
void mass_matrix(const T* q, T* M) {
  (void)q;
  M[0] = T(p::m * p::L * p::L + p::Iyy);
}

template <class T>
void forcing(const T* q, const T* u, const T* tau, T* F) {
  using std::cos;
  F[0] = T(p::m * p::g * p::L) * cos(q[0]) - T(p::k) * (q[0] - T(p::r0)) - T(p::c) * u[0] + tau[0];
}

template <class T>
int udot(const T* q, const T* u, const T* tau, T* ud) {
  T M, F;
  mass_matrix(q, &M);
  forcing(q, u, tau, &F);
  if (!(M > T(0))) return 1;
  ud[0] = F / M;
  return 0;
}

inline int jacobian(const double* q, const double* u, const double* tau, double* J) {
  (void)u;
  (void)tau;
  double M;
  mass_matrix(q, &M);
  if (!(M > 0)) return 1;
  // column-major 2x2 of [q'; u'] w.r.t. [q; u]
  J[0] = 0.0;
  J[1] = (-p::m * p::g * p::L * std::sin(q[0]) - p::k) / M;
  J[2] = 1.0;
  J[3] = -p::c / M;
  return 0;
}

template <class T>
void energy(const T* q, const T* u, T* TV) {
  using std::sin;
  T M;
  mass_matrix(q, &M);
  TV[0] = T(0.5) * M * u[0] * u[0];
  const T d = q[0] - T(p::r0);
  TV[1] = -T(p::m * p::g * p::L) * sin(q[0]) + T(0.5 * p::k) * d * d;
}

template <class T>
void momentum(const T* q, const T* u, T* pH) {
  using std::cos;
  using std::sin;
  T M;
  mass_matrix(q, &M);
  pH[0] = -T(p::m * p::L) * u[0] * sin(q[0]);
  pH[1] = T(0);
  pH[2] = -T(p::m * p::L) * u[0] * cos(q[0]);
  pH[3] = T(0);
  pH[4] = M * u[0];
  pH[5] = T(0);
}

}  // namespace kanegen_gen::pendulum_handwritten
