// Inertia terms of one body in its own velocity coordinates
// z = [v_O_B, w_B, eta_dot], from its mass integrals (modal_integrals.hpp).
// With s_k = rho_k + Phi_k eta the node positions, the body's kinetic energy is
// T = 1/2 z^T M_body(eta) z with
//   M_body = [ m I     -S^x    B  ]     S   = S0 + B eta           first moment
//            [ S^x     J_O     C  ]     J_O = inertia about O (exact in eta)
//            [ B^T     C^T     Y  ]     C   = Sum m_k s_k^x Phi_k  rotational participation
// and the element accelerations a_k = A_k z_dot + b_k, A_k = [I, -s_k^x, Phi_k],
// b_k = w x (w x s_k) + 2 w x Phi_k eta_dot give the velocity terms
//   h_v   = w x (w x S) + 2 w x (B eta_dot)
//   h_w   = w x (J_O w) + 2 (tr(G) w - G w),     G = Sum m_k (Phi_k eta_dot) s_k^T
//   h_eta = Sum m_k Phi_k^T (w x (w x s_k) + 2 w x Phi_k eta_dot)
// so that the generalized inertia force of the body is -(M_body z_dot + h).
//
// Nodes with rotary inertia or foreshortening ("rich" nodes) are added one by
// one (add_node_terms): a point mass at s_k = rho_k + Phi_k eta + 1/2
// gamma_k(eta), velocity v_O + w x s_k + Phi~_k eta_dot (Phi~_k = Phi_k +
// G_k(eta)), acceleration A_k z_dot + b_k with A_k = [I, -s_k^x, Phi~_k] and
// b_k = w x (w x s_k) + 2 w x Phi~_k eta_dot + [eta_dot^T Gamma_k^a eta_dot]_a;
// and a rotary inertia J_k carried by the node frame C(Psi_k eta): J'_k = C J_k
// C^T, angular velocity w_k = w + H_k eta_dot, H_k = (I + g^x) Psi_k / (1 + g.g),
// g = Psi_k eta / 2, angular acceleration Omega_k z_dot + beta_k with
// Omega_k = [0, I, H_k], beta_k = w x H_k eta_dot - (2 g.g_dot / (1 + g.g)) H_k eta_dot.
// They add m_k A_k^T A_k + Omega_k^T J'_k Omega_k to M_body,
// m_k A_k^T b_k + Omega_k^T (J'_k beta_k + w_k x J'_k w_k) to h and
// m_k A_k^T g_B to g: exact, nothing truncated in eta (dynamics.md).
#pragma once

#include "model/modal_integrals.hpp"
#include "model/model.hpp"
#include "model/rotation.hpp"

namespace kanegen {

namespace detail {
inline int levi(int a, int b, int c) { return (a - b) * (b - c) * (c - a) / 2; }
}  // namespace detail

/// Fills M_body, h_body and g_body (generalized gravity, g_B = gravity in B).
/// Q: 3 x 3 scratch vectors of size m (allocated by the caller, see workspace.hpp).
template <class S, class VecS, class MatS>
void compute_body_inertia(const BodyMassIntegrals& I, const VecS& eta, const VecS& eta_dot, const V3<S>& w,
                          const V3<S>& g_B, MatS& M_body, VecS& h_body, VecS& g_body, VecS (&Q)[3][3]) {
  const int m = I.m;
  const M3<S> I3 = M3<S>::Identity();
  V3<S> S_B = I.S0.cast<S>();
  if (m) S_B.noalias() += as_scalar<S>(I.B) * eta;
  M3<S> J_O = I.J0.cast<S>();
  V3<S> h_w_extra = V3<S>::Zero();
  V3<S> h_v_extra = V3<S>::Zero();
  M_body.setZero();
  if (m > 0) {
    // Q[a][b] = Sum m_k s_k[a] Phi_k[b,:]  (m-vectors, affine in eta)
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) {
        Q[a][c] = as_scalar<S>(I.Prf[a][c]);
        Q[a][c].noalias() += as_scalar<S>(I.Pff[a][c]).transpose() * eta;
      }
    // J_O(eta) = J0 + tr(D) I - D, D[a][b] = Sum m s_a s_b - Sum m rho_a rho_b
    M3<S> D;
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) D(a, c) = as_scalar<S>(I.Prf[c][a]).dot(eta) + Q[a][c].dot(eta);
    J_O += D.trace() * I3 - D;
    // C[a,i] = eps_abc Q[b][c]_i, written straight into M_body
    auto C = M_body.block(3, 6, 3, m);
    for (int a = 0; a < 3; ++a)
      for (int bb = 0; bb < 3; ++bb)
        for (int c = 0; c < 3; ++c) {
          const int e = detail::levi(a, bb, c);
          if (e != 0) C.row(a) += S(e) * Q[bb][c].transpose();
        }
    M_body.block(6, 3, m, 3) = C.transpose();
    const auto& B = as_scalar<S>(I.B);
    M_body.block(0, 6, 3, m) = B;
    M_body.block(6, 0, m, 3) = B.transpose();
    M_body.block(6, 6, m, m) = as_scalar<S>(I.Y);
    // Velocity terms.
    V3<S> B_eta_dot;
    B_eta_dot.noalias() = B * eta_dot;
    h_v_extra = S(2) * w.cross(B_eta_dot);
    M3<S> G;  // G[a][b] = Sum m (Phi eta_dot)_a s_b = Q[b][a] . eta_dot
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) G(a, c) = Q[c][a].dot(eta_dot);
    h_w_extra = S(2) * (G.trace() * w - G * w);
    auto h_eta = h_body.segment(6, m);
    h_eta.setZero();
    const S w2 = w.dot(w);
    for (int a = 0; a < 3; ++a) {
      h_eta -= w2 * Q[a][a];
      for (int c = 0; c < 3; ++c) {
        h_eta += (w(a) * w(c)) * Q[c][a];
        for (int bb = 0; bb < 3; ++bb) {
          const int e = detail::levi(a, bb, c);
          if (e != 0) h_eta.noalias() += ((S(2 * e) * w(bb)) * as_scalar<S>(I.Pff[a][c])) * eta_dot;
        }
      }
    }
    g_body.segment(6, m).noalias() = B.transpose() * g_B;
  }
  M_body.block(0, 0, 3, 3) = S(I.mass) * I3;
  M_body.block(0, 3, 3, 3) = -skew<S>(S_B);
  M_body.block(3, 0, 3, 3) = skew<S>(S_B);
  M_body.block(3, 3, 3, 3) = J_O;
  h_body.template head<3>() = w.cross(w.cross(S_B)) + h_v_extra;
  h_body.template segment<3>(3) = w.cross(J_O * w) + h_w_extra;
  g_body.template head<3>() = S(I.mass) * g_B;
  g_body.template segment<3>(3) = S_B.cross(g_B);
}

/// First mass moment about O of the integrated part (rigid part and plain nodes).
template <class S, class VecS>
V3<S> integrated_first_moment(const BodyMassIntegrals& I, const VecS& eta) {
  V3<S> S_B = I.S0.cast<S>();
  if (I.m) S_B.noalias() += as_scalar<S>(I.B) * eta;
  return S_B;
}

/// Node k's position s_k = rho_k + Phi_k eta (+ 1/2 gamma_k(eta) with second-order data) and its
/// derivative Phi~_k = Phi_k + G_k(eta) (3 x m), B components. tmp: m scratch.
template <class S, class VecS, class Mat3m>
V3<S> node_position(const FlexibleData& flex, int k, const VecS& eta, Mat3m& Phi_t, VecS& tmp) {
  V3<S> s_k = flex.nodes[k].rho_B.template cast<S>();
  Phi_t = as_scalar<S>(flex.Phi.template middleRows<3>(3 * k));
  if (flex.modes()) s_k.noalias() += Phi_t * eta;
  if (flex.has_second_order(k))
    for (int a = 0; a < 3; ++a) {
      const MatX& G = flex.Gamma[k][a];
      if (G.size() == 0) continue;
      tmp.noalias() = as_scalar<S>(G) * eta;
      s_k(a) += S(0.5) * eta.dot(tmp);
      Phi_t.row(a) += tmp.transpose();
    }
  return s_k;
}

/// Node k's frame C(Psi_k eta): its rotary inertia J'_k = C J_k C^T (B axes), and H_k (3 x m,
/// w_k = w + H_k eta_dot); g = Psi_k eta / 2 returned for the rate terms.
template <class S, class VecS, class Mat3m>
M3<S> node_rotary_inertia(const FlexibleData& flex, int k, const VecS& eta, Mat3m& H, V3<S>& g) {
  const int m = flex.modes();
  const auto Psi_k = as_scalar<S>(flex.Psi.template middleRows<3>(3 * k));
  V3<S> theta = V3<S>::Zero();
  if (m) theta.noalias() = Psi_k * eta;
  g = theta / S(2);
  const M3<S> C = rodrigues_R<S>(theta);
  if (m) {
    H.noalias() = (M3<S>::Identity() + skew<S>(g)) * Psi_k;
    H /= S(1) + g.dot(g);
  }
  return C * flex.nodes[k].J_B.template cast<S>() * C.transpose();
}

/// Adds node k of `flex` (a rich node) to M_body, h_body, g_body and to the
/// first moment S_B (header comment). Phi_t, H, JH: 3 x m scratch; tmp: m scratch.
template <class S, class VecS, class MatS, class Mat3m>
void add_node_terms(const FlexibleData& flex, int k, const VecS& eta, const VecS& eta_dot, const V3<S>& w,
                    const V3<S>& g_B, MatS& M_body, VecS& h_body, VecS& g_body, V3<S>& S_B, Mat3m& Phi_t, Mat3m& H,
                    Mat3m& JH, VecS& tmp) {
  const int m = flex.modes();
  const ModalNode& node = flex.nodes[k];
  const M3<S> I3 = M3<S>::Identity();
  if (node.mass != 0.0) {
    const S mk = S(node.mass);
    const V3<S> s_k = node_position<S>(flex, k, eta, Phi_t, tmp);
    V3<S> gamma_dd = V3<S>::Zero();  // [eta_dot^T Gamma^a eta_dot]_a
    if (flex.has_second_order(k))
      for (int a = 0; a < 3; ++a) {
        const MatX& G = flex.Gamma[k][a];
        if (G.size() == 0) continue;
        tmp.noalias() = as_scalar<S>(G) * eta_dot;
        gamma_dd(a) = eta_dot.dot(tmp);
      }
    const M3<S> sx = skew<S>(s_k);
    M_body.template block<3, 3>(0, 0) += mk * I3;
    M_body.template block<3, 3>(0, 3) -= mk * sx;
    M_body.template block<3, 3>(3, 0) += mk * sx;
    M_body.template block<3, 3>(3, 3) += mk * (s_k.squaredNorm() * I3 - s_k * s_k.transpose());
    V3<S> v_rel = V3<S>::Zero();
    if (m) {
      M_body.block(0, 6, 3, m) += mk * Phi_t;
      M_body.block(6, 0, m, 3) += mk * Phi_t.transpose();
      JH.noalias() = sx * Phi_t;  // JH as scratch: s_k^x Phi~_k
      M_body.block(3, 6, 3, m) += mk * JH;
      M_body.block(6, 3, m, 3) += mk * JH.transpose();
      M_body.block(6, 6, m, m).noalias() += (mk * Phi_t.transpose()) * Phi_t;
      v_rel.noalias() = Phi_t * eta_dot;
    }
    const V3<S> b = w.cross(w.cross(s_k)) + S(2) * w.cross(v_rel) + gamma_dd;
    h_body.template head<3>() += mk * b;
    h_body.template segment<3>(3) += mk * s_k.cross(b);
    g_body.template head<3>() += mk * g_B;
    g_body.template segment<3>(3) += mk * s_k.cross(g_B);
    if (m) {
      h_body.tail(m).noalias() += mk * Phi_t.transpose() * b;
      g_body.tail(m).noalias() += mk * Phi_t.transpose() * g_B;
    }
    S_B += mk * s_k;
  }
  if (!node.J_B.isZero(0.0)) {
    V3<S> g, g_dot = V3<S>::Zero();
    const M3<S> Jp = node_rotary_inertia<S>(flex, k, eta, H, g);
    if (m) {
      g_dot.noalias() = as_scalar<S>(flex.Psi.template middleRows<3>(3 * k)) * eta_dot;
      g_dot /= S(2);
    }
    const S denom = S(1) + g.dot(g);
    V3<S> w_rel = V3<S>::Zero();
    M_body.template block<3, 3>(3, 3) += Jp;
    if (m) {
      JH.noalias() = Jp * H;
      M_body.block(3, 6, 3, m) += JH;
      M_body.block(6, 3, m, 3) += JH.transpose();
      M_body.block(6, 6, m, m).noalias() += H.transpose() * JH;
      w_rel.noalias() = H * eta_dot;
    }
    const V3<S> w_k = w + w_rel;
    const V3<S> beta = w.cross(w_rel) - (S(2) * g.dot(g_dot) / denom) * w_rel;
    const V3<S> torque = Jp * beta + w_k.cross(Jp * w_k);
    h_body.template segment<3>(3) += torque;
    if (m) h_body.tail(m).noalias() += H.transpose() * torque;
  }
}

}  // namespace kanegen
