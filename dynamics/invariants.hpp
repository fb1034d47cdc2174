// Invariants (dynamics.md): E = T + V and, about N's origin in N components,
// p = Sum m v and H = Sum (r x m v + R_j I w_j). Each body's generalized
// momentum M_body z (z = [v_O_B, w_B, eta_dot]) holds its linear momentum and
// its angular momentum about O_B in its first six rows, and T = 1/2 Sum z^T M_body z.
// Requires compute_kinematics and compute_body_terms.
#pragma once

#include "dynamics/central_gravity.hpp"

#include "model/model.hpp"
#include "dynamics/workspace.hpp"

namespace kanegen {

template <class S>
struct Energy {
  S T = S(0);  ///< kinetic
  S V = S(0);  ///< gravity + joint springs + modal strain energy
};

template <class S>
struct Momentum {
  V3<S> p_N = V3<S>::Zero();
  V3<S> H_N = V3<S>::Zero();  ///< about N's origin
};

namespace detail {
/// s.z = [v_O_B, w_B, eta_dot] and s.Mz = M_body z, in the workspace's scratch (no allocation).
template <class S>
void body_momentum(BodyWorkspace<S>& s) {
  const auto m = s.eta_dot.size();
  s.z.template head<3>() = s.v_O_B;
  s.z.template segment<3>(3) = s.w_B;
  s.z.tail(m) = s.eta_dot;
  s.Mz.noalias() = s.M_body * s.z;
}
}  // namespace detail

template <class S, class VecQ>
Energy<S> compute_energy(const Model& model, Workspace<S>& ws, const VecQ& q) {
  Energy<S> E;
  const V3<S> g_N = model.g_N.cast<S>();
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const Body& b = model.bodies[i];
    BodyWorkspace<S>& s = ws.body[i];
    detail::body_momentum(s);
    E.T += S(0.5) * s.z.dot(s.Mz);
    E.V -= g_N.dot(S(b.total_mass) * s.r_NO_N + s.R_NB * s.S_B);
    const Joint& j = b.joint;
    for (const SpringSlot& sl : spring_slots(j))
      if (sl.q >= 0) {
        const S dq = S(q(b.q_joint + sl.q)) - S(j.rest[sl.value]);
        E.V += S(0.5 * j.stiffness[sl.value]) * dq * dq;
      }
    for (int k = 0; k < b.n_modes(); ++k) E.V += S(0.5 * b.flex->K(k)) * s.eta(k) * s.eta(k);
  }
  if (model.central) E.V += central_potential(model, ws);  // g_N is zero then
  return E;
}

template <class S>
Momentum<S> compute_momentum(const Model& model, Workspace<S>& ws) {
  Momentum<S> P;
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    BodyWorkspace<S>& s = ws.body[i];
    detail::body_momentum(s);
    const Eigen::Matrix<S, 6, 1> h = s.Mz.template head<6>();
    const V3<S> p_N = s.R_NB * h.template head<3>();
    P.p_N += p_N;
    P.H_N += s.r_NO_N.cross(p_N) + s.R_NB * h.template tail<3>();
  }
  return P;
}

}  // namespace kanegen
