// The named inputs w (model/inputs_outputs.hpp) as applied loads: each input's
// wrench on its body [force; torque about O_B] in body components, which
// forcing adds to the body's applied forces before projecting them on the
// partial velocities (Kane's generalized active forces) and which the
// reactions subtract from the wrench the body's mass needs; joint torques go
// straight to their joint's speed. Requires compute_kinematics (R_NB).
#pragma once

#include "dynamics/workspace.hpp"
#include "model/model.hpp"

namespace kanegen {

/// Adds the wrench of input `in` (values from w) to W, in the components of
/// the frame of the body `s` describes. Joint torques add nothing here.
template <class S, class VecW>
void add_input_wrench(const Input& in, const BodyWorkspace<S>& s, const VecW& w, Eigen::Matrix<S, 6, 1>& W) {
  const M3<S> R_BX = in.R_BX.template cast<S>();
  V3<S> f = V3<S>::Zero(), t = V3<S>::Zero();
  switch (in.type) {
    case InputType::thruster: f = in.direction_B.template cast<S>() * S(w(in.offset)); break;
    case InputType::force:
    case InputType::torque: {
      const V3<S> v(S(w(in.offset)), S(w(in.offset + 1)), S(w(in.offset + 2)));
      const V3<S> v_B = in.axes == Axes::inertial ? V3<S>(s.R_NB.transpose() * v) : V3<S>(R_BX * v);
      (in.type == InputType::force ? f : t) = v_B;
      break;
    }
    case InputType::joint_torque: return;
  }
  W.template head<3>() += f;
  W.template tail<3>() += t + in.point_B.template cast<S>().cross(f);
}

/// Adds input `in`'s generalized forces on body `b` to Y (6 + m rows, the
/// body's velocity coordinates [v_O_B, w_B, eta_dot]): its wrench, and for a
/// force at a node of a flexible body the node's displaced position and the
/// modal rows Phi~_k^T f (Phi~_k = Phi_k + G_k(eta): the node's velocity per
/// modal speed, with foreshortening).
template <class S, class VecW, class VecY>
void add_input_generalized_force(const Input& in, const Body& b, const BodyWorkspace<S>& s, const VecW& w, VecY& Y) {
  if (in.node < 0) {
    Eigen::Matrix<S, 6, 1> W = Eigen::Matrix<S, 6, 1>::Zero();
    add_input_wrench(in, s, w, W);
    Y.template head<6>() += W;
    return;
  }
  const FlexibleData& f = *b.flex;
  const int k = in.node, m = f.modes();
  const V3<S> v(S(w(in.offset)), S(w(in.offset + 1)), S(w(in.offset + 2)));
  const V3<S> f_B = in.axes == Axes::inertial ? V3<S>(s.R_NB.transpose() * v) : V3<S>(in.R_BX.template cast<S>() * v);
  V3<S> s_k = f.nodes[k].rho_B.template cast<S>();
  Eigen::Matrix<S, 3, Eigen::Dynamic> Phi_t = f.Phi.middleRows(3 * k, 3).template cast<S>();
  if (m) s_k += Phi_t * s.eta;
  if (f.has_second_order(k))
    for (int a = 0; a < 3; ++a)
      if (f.Gamma[k][a].size()) {
        const Eigen::Matrix<S, Eigen::Dynamic, 1> Ge = f.Gamma[k][a].template cast<S>() * s.eta;
        s_k(a) += S(0.5) * s.eta.dot(Ge);
        Phi_t.row(a) += Ge.transpose();
      }
  Y.template head<3>() += f_B;
  Y.template segment<3>(3) += s_k.cross(f_B);
  if (m) Y.segment(6, m) += Phi_t.transpose() * f_B;
}

/// Adds the joint-torque inputs to the generalized forces F.
template <class VecW, class VecF>
void add_joint_inputs(const Model& model, const VecW& w, VecF& F) {
  for (const Input& in : model.inputs)
    if (in.type == InputType::joint_torque)
      for (int k = 0; k < in.speeds; ++k) F(model.bodies[in.body].u_joint + in.speed + k) += w(in.offset + k);
}

}  // namespace kanegen
