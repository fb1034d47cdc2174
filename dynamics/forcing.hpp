// F(q, u, tau) = tau + joint springs/dampers + modal stiffness/damping
//              + Sum_j P_j^T (g_body - M_body z_R - h_body),
// z_R = [a_R_B, alpha_R_B, 0] the body's remainder accelerations: the
// generalized active forces (gravity on every mass element) plus the
// generalized inertia forces without their u-dot part (dynamics.md).
// Requires compute_kinematics and compute_body_terms.
#pragma once

#include "model/model.hpp"
#include "dynamics/applied_inputs.hpp"
#include "dynamics/workspace.hpp"

namespace kanegen {

/// Joint spring/damper and modal stiffness/damping forces, added to F.
template <class S, class VecF, class VecQ, class VecU>
void add_elastic_forces(const Model& model, const VecQ& q, const VecU& u, VecF& F) {
  for (const Body& b : model.bodies) {
    const Joint& j = b.joint;
    for (const SpringSlot& sl : spring_slots(j)) {
      const int k = sl.value;
      if (j.stiffness[k] == 0 && j.damping[k] == 0) continue;
      S f = S(j.damping[k]) * S(u(b.u_joint + sl.u));
      if (sl.q >= 0) f += S(j.stiffness[k]) * (S(q(b.q_joint + sl.q)) - S(j.rest[k]));
      F(b.u_joint + sl.u) -= f;
    }
    for (int k = 0; k < b.n_modes(); ++k)
      F(b.u_eta + k) -= S(b.flex->K(k)) * S(q(b.q_eta + k)) + S(b.flex->D(k)) * S(u(b.u_eta + k));
  }
}

/// `w`: the named inputs (model.nw values; dynamics/applied_inputs.hpp).
template <class S, class VecQ, class VecU, class VecT, class VecW>
void compute_forcing(const Model& model, Workspace<S>& ws, const VecQ& q, const VecU& u, const VecT& tau,
                     const VecW& w) {
  for (int r = 0; r < model.nu; ++r) ws.F(r) = S(tau(r));
  add_elastic_forces<S>(model, q, u, ws.F);
  add_joint_inputs(model, w, ws.F);
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const std::vector<int>& chain = model.bodies[i].chain_u;
    BodyWorkspace<S>& s = ws.body[i];
    // y = g_body - M_body z_R - h_body, with z_R = [a_R, alpha_R, 0]
    s.z_dot = s.g_body - s.h_body;
    s.z_dot.noalias() -= s.M_body.template leftCols<3>() * s.a_R_B;
    s.z_dot.noalias() -= s.M_body.template middleCols<3>(3) * s.alpha_R_B;
    for (const Input& in : model.inputs)
      if (in.body == static_cast<int>(i) && in.type != InputType::joint_torque)
        add_input_generalized_force(in, model.bodies[i], s, w, s.z_dot);
    for (std::size_t c = 0; c < chain.size(); ++c) ws.F(chain[c]) += s.P.col(c).dot(s.z_dot);
  }
}

}  // namespace kanegen
