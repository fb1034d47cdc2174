// The symbolic formulation of Kane's equations for one Model, recursive along
// the kinematic chains (the structure of the paper's Eqs. 4-9), written into
// a Program as straight-line code:
//   outward pass   orientations, velocities, remainder accelerations and the
//                  joint transforms Xe (the partial-velocity recursion
//                  P_child = Xe P_parent + S), per body;
//   body terms     generalized mass M_body(eta), velocity terms h, gravity g;
//   forcing        F = tau + elastic + S^T W, W_j = g_j - M_j z_R,j - h_j +
//                  Sum_children Xe^T W_c (inward pass, O(n));
//   mass matrix    composite inertias Ic_j = M_j + Sum Xe^T Ic_c Xe and the
//                  column walk to the root (O(n * depth)), = Sum P^T M_body P;
//   solve          L^T D L factorization along the dof parent array, so the
//                  zero blocks between kinematic chains cause no fill-in;
//   reactions      inward Newton-Euler pass with the accelerations;
//   energy, momentum.
// Body velocity coordinates are z_j = [v_O (B), w (B), eta_dot] as in the
// generic engine (body_inertia.hpp), which the generated code cross-checks.
#pragma once

#include <string>
#include <vector>

#include "model.hpp"
#include "symbolic_algebra.hpp"

namespace kanegen::gen {

/// Symbols of the state arrays, printed as q[i], u[i], tau[i], udot_in[i].
struct StateSymbols {
  std::vector<ex> q, u, tau, udot;
  explicit StateSymbols(const Model& m);
};

struct SymBody {
  SM3 R_PB, R_NB;
  SV3 d;            // O_B from the parent origin, parent components
  SV3 r_NO;         // O_B in N
  SV3 w, v;         // angular velocity, velocity of O_B (B components)
  SV3 aR, alR;      // remainder accelerations (B components)
  std::vector<ex> eta, eta_dot;
  std::vector<std::array<ex, 6>> N;  // node coupling: extra partials per parent mode (B components)
  SMat Mb;                           // (6+m)^2
  std::vector<ex> h, g;              // 6+m
};

class KaneBuilder {
 public:
  KaneBuilder(const Model& model, Program& program, Constants& constants, const StateSymbols& x);

  /// Outward pass; velocities only when `with_velocity` (M needs none).
  void kinematics(bool with_velocity);
  /// Body inertia, velocity and gravity terms (after kinematics).
  void body_terms(bool with_velocity);
  /// kinematics() then body_terms(): what every dynamics function starts with.
  void prepare(bool with_velocity) {
    kinematics(with_velocity);
    body_terms(with_velocity);
  }
  std::vector<ex> forcing();
  /// u_dot by the articulated-body recursion (O(n)); binds the pivots of
  /// every joint's D matrix.
  std::vector<ex> udot_articulated(std::vector<ex>& pivots);
  SMat mass_matrix();
  /// Solves M x = b by L^T D L along the dof tree; binds `pivots` (D_ii).
  std::vector<ex> solve(SMat M, std::vector<ex> b, std::vector<ex>& pivots);
  /// 6 entries per body: reaction [force; torque about O_B] (B components).
  std::vector<ex> reactions(const std::vector<ex>& udot);
  ex kinetic_energy();
  ex potential_energy();
  /// p_N[3], H_N[3]
  std::vector<ex> momentum();
  std::vector<ex> qdot();

  const std::vector<SymBody>& bodies() const { return body_; }

 private:
  ex c(double v, const std::string& name, const std::string& unit, const std::string& what);
  SV3 cvec(const Vec3& v, const std::string& name, const std::string& unit, const std::string& what);
  SM3 cmat(const Mat3& m, const std::string& name, const std::string& unit, const std::string& what,
           bool symmetric = false);
  /// Xe applied to the parent's (6 + m_p) motion: the first 6 rows of body j's
  /// (6 + m_j) motion (the rest zero); all zero for a root (dp null).
  std::vector<ex> transform_motion_from_parent(int j, const std::vector<ex>* dp);
  /// Xe^T applied to a 6-vector W of child c: returns the parent's (6 + m_p) contribution.
  std::vector<ex> transform_wrench_to_parent(int c, const std::vector<ex>& W6);
  /// Motion subspace S of body j: own columns (joint then modes) as (6+m) vectors.
  std::vector<std::vector<ex>> motion_subspace(int j);
  std::vector<int> own_columns(int j) const;
  /// y_j = g_j - h_j - M_body z_R for every body (generalized gravity and
  /// velocity forces with the remainder accelerations' inertia forces).
  std::vector<std::vector<ex>> bias_forces();
  /// tau + spring/damper or modal stiffness/damping of body j's k-th own speed.
  ex applied_force(int j, int k);
  /// Inverse of a small symmetric positive-definite matrix by L D L^T; appends its pivots.
  SMat spd_inverse(const SMat& D, std::vector<ex>& pivots);

  const Model& model_;
  Program& P_;
  Constants& C_;
  const StateSymbols& x_;
  Alg A_;
  std::vector<SymBody> body_;
  std::vector<SMat> Ic_;
};

}  // namespace kanegen::gen
