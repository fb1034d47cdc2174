// Preallocated per-evaluation data of the generic engine (Pinocchio's "Data"):
// sized once from a Model, reused for every evaluation, no allocation per call.
// Frames in names: X_B = components in the body frame B, X_P = in the parent
// frame, X_N = in the inertial frame.
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "model/model.hpp"
#include "model/rotation.hpp"
#include "model/joints/joint_kinematics.hpp"

namespace kanegen {

template <class S>
struct BodyWorkspace {
  using MatS = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  using VecS = Eigen::Matrix<S, Eigen::Dynamic, 1>;

  M3<S> R_PB;        ///< orientation of B in the parent frame (x_P = R_PB x_B)
  V3<S> p_PO_P;      ///< O_B relative to the parent's origin, parent components
  M3<S> R_PJ;        ///< the joint frame J in the parent (its `rotation:`; at a node, turned with the node)
  V3<S> p_PJ_P;      ///< J's origin from the parent's origin (at a node: the node's displaced position), P components
  M3<S> R_NB;        ///< orientation of B in N
  V3<S> r_NO_N;      ///< O_B relative to N's origin, N components
  V3<S> v_O_B;       ///< inertial velocity of O_B, B components
  V3<S> w_B;         ///< inertial angular velocity of B, B components
  V3<S> a_R_B;       ///< remainder acceleration of O_B (terms without u-dot), B components
  V3<S> alpha_R_B;   ///< remainder angular acceleration of B, B components
  VecS eta;          ///< m modal coordinates
  VecS eta_dot;      ///< m modal speeds
  /// Partial velocities, (6 + m) x k over the body's chain_u columns:
  /// rows 0-2 linear of O_B (the paper's V block, B components), rows 3-5
  /// angular (the Omega block), rows 6.. modal speeds (identity on own modes).
  MatS P;
  MatS M_body;       ///< (6+m)^2 generalized mass of the body in [v_O_B, w_B, eta_dot]
  VecS h_body;       ///< 6+m  velocity-dependent inertia terms (centrifugal, Coriolis, gyroscopic)
  VecS g_body;       ///< 6+m  generalized gravity force on the body
  VecS z_dot;        ///< 6+m  scratch: body accelerations [a_O_B, alpha_B, eta_ddot]
  VecS z;            ///< 6+m  scratch: body speeds [v_O_B, w_B, eta_dot] (invariants.hpp)
  VecS Mz;           ///< 6+m  scratch: generalized momentum M_body z
  MatS MP;           ///< (6+m) x k scratch: M_body * P
  Eigen::Matrix<S, 6, 1> wrench_B;  ///< reaction on the body from its parent [force; torque about O_B], B
  Eigen::Matrix<S, 3, Eigen::Dynamic> H_node;  ///< 3 x m_parent: w_J = H eta_dot_parent (at a node)
  Eigen::Matrix<S, 3, Eigen::Dynamic> Phi_node;  ///< 3 x m_parent: v_node = Phi~ eta_dot_parent (at a node)
  VecS Gx_node;      ///< m_parent scratch: Gamma_k^a times eta or eta_dot (at a node)
  V3<S> S_B;         ///< first mass moment about O_B of the whole body (rigid part and every node), B
  // Scratch of the node-by-node terms (body_inertia.hpp, add_node_terms):
  Eigen::Matrix<S, 3, Eigen::Dynamic> node_Phi;  ///< 3 x m: Phi~_k = Phi_k + G_k(eta)
  Eigen::Matrix<S, 3, Eigen::Dynamic> node_H;    ///< 3 x m: node frame's angular velocity per eta_dot
  Eigen::Matrix<S, 3, Eigen::Dynamic> node_JH;   ///< 3 x m: J'_k H
  VecS node_m;       ///< m scratch
  VecS Q[3][3];      ///< m each: Sum m_k s_k[a] Phi_k[b,:] (body_inertia.hpp scratch)
};

template <class S>
struct Workspace {
  using MatS = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  using VecS = Eigen::Matrix<S, Eigen::Dynamic, 1>;

  explicit Workspace(const Model& model) {
    body.resize(model.bodies.size());
    for (std::size_t i = 0; i < model.bodies.size(); ++i) {
      const Body& b = model.bodies[i];
      const int m = b.n_modes();
      const int k = static_cast<int>(b.chain_u.size());
      BodyWorkspace<S>& w = body[i];
      w.eta = VecS::Zero(m);
      w.eta_dot = VecS::Zero(m);
      w.P = MatS::Zero(6 + m, k);
      w.M_body = MatS::Zero(6 + m, 6 + m);
      w.h_body = VecS::Zero(6 + m);
      w.g_body = VecS::Zero(6 + m);
      w.z_dot = VecS::Zero(6 + m);
      w.z = VecS::Zero(6 + m);
      w.Mz = VecS::Zero(6 + m);
      w.MP = MatS::Zero(6 + m, k);
      const int m_parent = b.parent >= 0 ? model.bodies[b.parent].n_modes() : 0;
      w.H_node = Eigen::Matrix<S, 3, Eigen::Dynamic>::Zero(3, b.joint.node >= 0 ? m_parent : 0);
      w.Phi_node = Eigen::Matrix<S, 3, Eigen::Dynamic>::Zero(3, b.joint.node >= 0 ? m_parent : 0);
      w.Gx_node = VecS::Zero(b.joint.node >= 0 ? m_parent : 0);
      w.node_Phi = Eigen::Matrix<S, 3, Eigen::Dynamic>::Zero(3, m);
      w.node_H = Eigen::Matrix<S, 3, Eigen::Dynamic>::Zero(3, m);
      w.node_JH = Eigen::Matrix<S, 3, Eigen::Dynamic>::Zero(3, m);
      w.node_m = VecS::Zero(m);
      for (auto& row : w.Q)
        for (auto& v : row) v = VecS::Zero(m);
    }
    for (const Body& b : model.bodies) {
      std::vector<joints::Vec<S>> axes;
      for (const auto& p : b.primitives) axes.push_back({S(p.axis(0)), S(p.axis(1)), S(p.axis(2))});
      primitive_axes.push_back(std::move(axes));
    }
    M = MatS::Zero(model.nu, model.nu);
    F = VecS::Zero(model.nu);
    udot = VecS::Zero(model.nu);
  }

  std::vector<BodyWorkspace<S>> body;
  /// Per body: the axes of its joint's primitives (Body::primitives) as S.
  std::vector<std::vector<joints::Vec<S>>> primitive_axes;
  MatS M;      ///< nu x nu mass matrix
  VecS F;      ///< nu forcing
  VecS udot;   ///< nu accelerations
};

}  // namespace kanegen
