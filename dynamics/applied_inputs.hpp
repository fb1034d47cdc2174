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

/// Adds the joint-torque inputs to the generalized forces F.
template <class VecW, class VecF>
void add_joint_inputs(const Model& model, const VecW& w, VecF& F) {
  for (const Input& in : model.inputs)
    if (in.type == InputType::joint_torque) F(model.bodies[in.body].u_joint) += w(in.offset);
}

}  // namespace kanegen
