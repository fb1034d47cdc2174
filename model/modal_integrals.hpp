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

namespace kanegen {

struct BodyMassIntegrals {
  int m = 0;                                    ///< number of modes
  double mass = 0.0;
  Eigen::Vector3d S0 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d J0 = Eigen::Matrix3d::Zero();
  Eigen::MatrixXd B;                            ///< 3 x m
  Eigen::MatrixXd Y;                            ///< m x m
  std::array<std::array<Eigen::VectorXd, 3>, 3> Prf;  ///< [a][b]: m
  std::array<std::array<Eigen::MatrixXd, 3>, 3> Pff;  ///< [a][b]: m x m
};

struct RigidPart;
struct FlexibleData;

/// Integrals of a rigid part and (optionally) a modal model.
BodyMassIntegrals compute_mass_integrals(const RigidPart& rigid, const FlexibleData* flex);

}  // namespace kanegen
