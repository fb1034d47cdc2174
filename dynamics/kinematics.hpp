// Forward kinematics along the kinematic chains (parents first): body
// orientations and positions, velocities, the partial velocity matrices
// (the paper's V and Omega blocks, Eqs. 4-5) and the remainder accelerations
// (Eqs. 6-8), all in body components, for rigid and flexible bodies and
// children attached at nodes of flexible parents (dynamics.md).
//
// For child B of parent P through joint frame J:
//   R_PB = R_PJ R_JB,   p_PO = p_PJ + e,   e = R_PJ delta (translation in the joint)
//   w_B  = w_P + w_J + w_rel            (w_J: rate of J in P, from the node's rotation)
//   v_O  = v_P + w_P x p_PO + v_rel,    v_rel = Phi_k eta_dot_P + w_J x e + e_dot
// and the remainders (u-dot terms removed):
//   alpha_R = alpha_R_P + w_P x (w_J + w_rel) + w_J_dot_R + w_J x w_rel
//   a_R     = a_R_P + alpha_R_P x p_PO + w_P x (w_P x p_PO) + 2 w_P x v_rel
//             + w_J_dot_R x e + w_J x (w_J x e) + w_J x e_dot + (w_J + w_rel) x e_dot
// At a node k with rotational shapes Psi_k: R_PJ = C(Psi_k eta_P) R_J0 (Rodrigues,
// g = Psi_k eta_P / 2), w_J = (I + g^x) Psi_k eta_dot_P / (1 + g.g) and
// w_J_dot_R = -(2 g.g_dot / (1 + g.g)) w_J. The node's displaced position is
// p_PJ = rho_k + Phi_k eta_P + 1/2 gamma_k(eta_P) (foreshortening), so its
// velocity is v_node = Phi~_k eta_dot_P with Phi~_k = Phi_k + G_k(eta_P)
// (row a of G_k: (Gamma_k^a eta_P)^T) and its acceleration gains the
// remainder [eta_dot_P^T Gamma_k^a eta_dot_P]_a.
// A prescribed joint (motion:) moves as a degree of freedom would with
// q = f(t), u = f_dot(t) but has no partial-velocity column: its known
// acceleration f_ddot times that column (the axis, angular for a revolute
// joint, linear for a prismatic one) joins the remainder accelerations.
#pragma once

#include <cmath>

#include "model/model.hpp"
#include "model/rotation.hpp"
#include "model/joints/joint_kinematics.hpp"
#include "dynamics/workspace.hpp"

namespace kanegen {

template <class S, class VecQ, class VecU>
void compute_kinematics(const Model& model, Workspace<S>& ws, double t, const VecQ& q, const VecU& u) {
  using std::sqrt;
  const M3<S> I3 = M3<S>::Identity();
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const Body& b = model.bodies[i];
    BodyWorkspace<S>& s = ws.body[i];
    const int m = b.n_modes();
    for (int k = 0; k < m; ++k) {
      s.eta(k) = S(q(b.q_eta + k));
      s.eta_dot(k) = S(u(b.u_eta + k));
    }

    // Parent state (ground: at rest, identity).
    const bool has_parent = b.parent >= 0;
    const BodyWorkspace<S>* p = has_parent ? &ws.body[b.parent] : nullptr;
    const V3<S> w_P = has_parent ? p->w_B : V3<S>::Zero();
    const V3<S> v_P = has_parent ? p->v_O_B : V3<S>::Zero();
    const V3<S> aR_P = has_parent ? p->a_R_B : V3<S>::Zero();
    const V3<S> alR_P = has_parent ? p->alpha_R_B : V3<S>::Zero();

    // Joint frame in the parent, and its motion when attached at a node.
    M3<S> R_PJ = b.joint.R_PJ.cast<S>();
    V3<S> p_PJ = b.joint.p_PJ.cast<S>();
    V3<S> w_J = V3<S>::Zero();        // angular velocity of J relative to P, P components
    V3<S> w_J_dot_R = V3<S>::Zero();  // its remainder rate
    V3<S> v_node = V3<S>::Zero();     // Phi~_k eta_dot_P
    V3<S> a_node_R = V3<S>::Zero();   // [eta_dot_P^T Gamma_k^a eta_dot_P]_a
    auto& H = s.H_node;
    auto& Phi_t = s.Phi_node;         // Phi~_k = Phi_k + G_k(eta_P)
    const int m_P = has_parent ? model.bodies[b.parent].n_modes() : 0;
    const FlexibleData* pf_ptr = b.joint.node >= 0 ? &*model.bodies[b.parent].flex : nullptr;
    if (b.joint.node >= 0) {
      const FlexibleData& pf = *pf_ptr;
      const int k = b.joint.node;
      const auto Phi_k = as_scalar<S>(pf.Phi.template middleRows<3>(3 * k));
      const auto Psi_k = as_scalar<S>(pf.Psi.template middleRows<3>(3 * k));
      const V3<S> theta = Psi_k * p->eta;
      const V3<S> g = theta / S(2);
      const S denom = S(1) + g.dot(g);
      R_PJ = rodrigues_R<S>(theta) * R_PJ;
      p_PJ = pf.nodes[k].rho_B.cast<S>() + Phi_k * p->eta;
      Phi_t = Phi_k;
      if (pf.has_second_order(k)) {
        auto& Gx = s.Gx_node;  // scratch, m_P
        for (int a = 0; a < 3; ++a) {
          const MatX& G = pf.Gamma[k][a];
          if (G.size() == 0) continue;
          Gx.noalias() = as_scalar<S>(G) * p->eta;
          p_PJ(a) += S(0.5) * p->eta.dot(Gx);
          Phi_t.row(a) += Gx.transpose();
          Gx.noalias() = as_scalar<S>(G) * p->eta_dot;
          a_node_R(a) = p->eta_dot.dot(Gx);
        }
      }
      H.noalias() = (I3 + skew<S>(g)) * Psi_k;
      H /= denom;
      w_J = H * p->eta_dot;
      const V3<S> g_dot = Psi_k * p->eta_dot / S(2);
      w_J_dot_R = -(S(2) * g.dot(g_dot) / denom) * w_J;
      v_node = Phi_t * p->eta_dot;
    }

    // Joint motion, asked of the joint's traits (model/joints/joint_kinematics.hpp):
    // R_JB, the offset e_J, the motion subspace (B components) and its rate.
    // A prescribed joint moves with its motion's value and rate at t; its known
    // acceleration times its column joins the remainders below.
    const int nu_j = joint_traits(b.joint.type).nu();
    S qj[kMaxJointCoordinates], uj[kMaxJointSpeeds];
    MotionValue mv{};
    if (b.joint.prescribed()) {
      mv = b.joint.motion->at(t);
      qj[0] = S(mv.f), uj[0] = S(mv.f_dot);
    } else {
      for (int k = 0; k < joint_nq(b.joint); ++k) qj[k] = S(q(b.q_joint + k));
      for (int k = 0; k < nu_j; ++k) uj[k] = S(u(b.u_joint + k));
    }
    const auto& prims = b.primitives;
    const auto jm = joints::joint_motion<S>(prims, ws.primitive_axes[i], nu_j, qj, uj, true, [](const S& x) { return x; });
    M3<S> R_JB;
    V3<S> e_J, w_rel_B, e_dot_B, bias_w_B, bias_v_B;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) R_JB(r, c) = jm.R_JB[r][c];
      e_J(r) = jm.e_J[r], w_rel_B(r) = jm.w_rel_B[r], e_dot_B(r) = jm.e_dot_B[r];
      bias_w_B(r) = jm.bias_w_B[r], bias_v_B(r) = jm.bias_v_B[r];
    }
    if (b.joint.prescribed())
      for (int r = 0; r < 3; ++r)
        bias_w_B(r) += jm.Sw[0][r] * S(mv.f_ddot), bias_v_B(r) += jm.Sv[0][r] * S(mv.f_ddot);
    const M3<S> R_PB_j = R_PJ * R_JB;
    const V3<S> e = R_PJ * e_J;                 // O_B - origin of J, P components
    const V3<S> e_dot = R_PB_j * e_dot_B;       // its rate seen in J, P components
    const V3<S> w_rel = R_PB_j * w_rel_B;       // angular velocity of B relative to J, P components
    s.R_PB = R_PB_j;
    s.p_PO_P = p_PJ + e;
    s.R_PJ = R_PJ;
    s.p_PJ_P = p_PJ;
    const M3<S> R_BP = s.R_PB.transpose();
    const V3<S>& d = s.p_PO_P;

    // Velocities and remainder accelerations, parent components, then into B.
    const V3<S> w_BP = w_J + w_rel;
    const V3<S> v_rel = v_node + w_J.cross(e) + e_dot;
    s.w_B = R_BP * (w_P + w_BP);
    s.v_O_B = R_BP * (v_P + w_P.cross(d) + v_rel);
    s.alpha_R_B = R_BP * (alR_P + w_P.cross(w_BP) + w_J_dot_R + w_J.cross(w_rel));
    s.a_R_B = R_BP * (aR_P + alR_P.cross(d) + w_P.cross(w_P.cross(d)) + S(2) * w_P.cross(v_rel) +
                      w_J_dot_R.cross(e) + w_J.cross(w_J.cross(e)) + w_J.cross(e_dot) + w_BP.cross(e_dot) + a_node_R);
    // the motion subspace's own rate (zero for constant columns)
    s.alpha_R_B += bias_w_B;
    s.a_R_B += bias_v_B;
    if (has_parent) {
      s.R_NB = p->R_NB * s.R_PB;
      s.r_NO_N = p->r_NO_N + p->R_NB * d;
    } else {
      s.R_NB = s.R_PB;
      s.r_NO_N = d;
    }

    // Partial velocities: the parent's chain carried across the joint ...
    s.P.setZero();
    const int k_P = has_parent ? static_cast<int>(p->P.cols()) : 0;
    if (has_parent) {
      const auto V_P = p->P.topRows(3);
      const auto W_P = p->P.middleRows(3, 3);
      // V_B = R_BP (V_P + W_P x d) = R_BP V_P - R_BP d^x W_P ; W_B = R_BP W_P
      s.P.topLeftCorner(3, k_P).noalias() = R_BP * V_P;
      s.P.topLeftCorner(3, k_P).noalias() -= (R_BP * skew<S>(d)) * W_P;
      s.P.block(3, 0, 3, k_P).noalias() = R_BP * W_P;
      if (b.joint.node >= 0) {  // ... plus the node's motion driven by the parent's modes
        const int c0 = k_P - m_P;
        s.P.block(0, c0, 3, m_P).noalias() += R_BP * Phi_t;
        s.P.block(0, c0, 3, m_P).noalias() -= (R_BP * skew<S>(e)) * H;
        s.P.block(3, c0, 3, m_P).noalias() += R_BP * H;
      }
    }
    // ... then the joint's own columns (its motion subspace, B components) ...
    if (!b.joint.prescribed())
      for (int c = 0; c < nu_j; ++c)
        for (int r = 0; r < 3; ++r) s.P(r, k_P + c) = jm.Sv[c][r], s.P(3 + r, k_P + c) = jm.Sw[c][r];
    // ... and the body's own modal speeds.
    const int c_eta = k_P + joint_nu(b.joint);
    for (int k = 0; k < m; ++k) s.P(6 + k, c_eta + k) = S(1);
  }
}

}  // namespace kanegen
