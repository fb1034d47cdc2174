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
#pragma once

#include "model/modal_integrals.hpp"
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

}  // namespace kanegen
