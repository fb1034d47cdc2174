// Mass integrals of one body (its rigid part plus the plain nodes of its
// modal model: those without rotary inertia or foreshortening, whose terms
// are polynomials in eta), precomputed once at load so that evaluating them
// costs O(m^2) for m modes, independently of the number of nodes. The other
// ("rich") nodes are handled one by one (dynamics/body_inertia.hpp).
//
// With plain node k at s_k(eta) = rho_k + Phi_k eta (B components), mass m_k,
// and the rigid part (m_r, c, I_c):
//   mass   = m_r + Sum m_k
//   S0     = m_r c + Sum m_k rho_k                        first moment at eta = 0
//   J0     = I_c + m_r(|c|^2 I - c c^T)                   inertia about O of the
//            + Sum m_k (|rho_k|^2 I - rho_k rho_k^T)      undeformed body
//   B      = Sum m_k Phi_k                   (3 x m)      translational participation
//   Y      = Sum m_k Phi_k^T Phi_k           (m x m)      modal mass
//   Prf[a][b] = Sum m_k rho_k[a] Phi_k[b,:]  (m-vector)   first-order coupling
//   Pff[a][b] = Sum m_k Phi_k[a,:]^T Phi_k[b,:]  (m x m)  second-order coupling
// Every eta-dependent quantity of the kinetic energy (first moment, inertia
// about O, rotational participation, centrifugal and Coriolis terms) is a
// polynomial in eta whose coefficients are these; nothing is truncated.
// The paper's B, C, Y, N, L, D integrals are all combinations of them.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <vector>

namespace kanegen {

/// The rich nodes' point masses (nodes with foreshortening or rotary inertia, handled one by one), summed
/// where the sum over nodes is a polynomial in eta of degree 2 at most, so that the generated code evaluates
/// it at a cost independent of the number of nodes (issue 38, item 2). With Phi~_k = Phi_k + G_k(eta) (row a
/// of G_k: (Gamma_k^a eta)^T) and s_k = rho_k + Phi_k eta + 1/2 gamma_k(eta), over the rich nodes:
///   mass = Sum m_k,  S0 = Sum m_k rho_k,  B = Sum m_k Phi_k (3 x m),  G[a] = Sum m_k Gamma_k^a (m x m)
///     Sum m_k s_k        = S0 + B eta + 1/2 [eta^T G[a] eta]_a
///     Sum m_k Phi~_k     = B + [G[a] eta]^T_a                      (3 x m)
///     Sum m_k eta_dot^T Gamma_k^a eta_dot = eta_dot^T G[a] eta_dot
///   Y = Sum m_k Phi_k^T Phi_k (m x m), and for modes i, l (index i m + l):
///     Y1[i m + l](p)   = Sum m_k Sum_a (Phi_k[a,i] Gamma_k^a(l,p) + Phi_k[a,l] Gamma_k^a(i,p))
///     Y2[i m + l](p,r) = Sum m_k Sum_a Gamma_k^a(i,p) Gamma_k^a(l,r), symmetrized in p, r
///     Sum m_k Phi~_k,i . Phi~_k,l = Y(i,l) + Y1[i m + l] . eta + eta^T Y2[i m + l] eta
/// Gamma_k^a as the generator reads it: its upper triangle, mirrored. The sums of degree 3 and 4
/// (Sum m s x Phi~, Sum m s s^T) and the rotary inertia stay node by node; the generic engine keeps every
/// node's terms one by one (an independent check of these sums).
/// Empty (nodes = 0, no storage) for a body without rich nodes of mass; Y1 and Y2 (m^4 / 4 numbers) only up to
/// kMaxModesModalMass modes and only for i <= l (beyond, the generated code forms that block node by node).
struct RichNodeSums {
  static constexpr int kMaxModesModalMass = 16;
  int nodes = 0;                                ///< rich nodes with mass
  double mass = 0.0;
  Eigen::Vector3d S0 = Eigen::Vector3d::Zero();
  Eigen::MatrixXd B;                            ///< 3 x m
  std::array<Eigen::MatrixXd, 3> G;             ///< m x m each
  Eigen::MatrixXd Y;                            ///< m x m (zero beyond kMaxModesModalMass)
  std::vector<Eigen::VectorXd> Y1;              ///< [i m + l], i <= l: m (empty beyond kMaxModesModalMass)
  std::vector<Eigen::MatrixXd> Y2;              ///< [i m + l], i <= l: m x m (empty likewise)
};

struct BodyMassIntegrals {
  int m = 0;                                    ///< number of modes
  double mass = 0.0;
  Eigen::Vector3d S0 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d J0 = Eigen::Matrix3d::Zero();
  Eigen::MatrixXd B;                            ///< 3 x m
  Eigen::MatrixXd Y;                            ///< m x m
  std::array<std::array<Eigen::VectorXd, 3>, 3> Prf;  ///< [a][b]: m
  std::array<std::array<Eigen::MatrixXd, 3>, 3> Pff;  ///< [a][b]: m x m
  RichNodeSums rich;                            ///< the rich nodes' point masses, to degree 2 in eta
};

struct RigidPart;
struct FlexibleData;

/// Integrals of a rigid part and (optionally) a modal model.
BodyMassIntegrals compute_mass_integrals(const RigidPart& rigid, const FlexibleData* flex);

}  // namespace kanegen
