// q_dot = W(q) u (dynamics.md joint table), each joint's asked of its traits
// (model/joints/joint_kinematics.hpp, joint_qdot); modal coordinates: eta_dot = u.
#pragma once

#include "model/model.hpp"
#include "model/rotation.hpp"
#include "model/joints/joint_kinematics.hpp"

namespace kanegen {

template <class S, class VecQ, class VecU, class VecQd>
void compute_qdot(const Model& model, const VecQ& q, const VecU& u, VecQd& qdot) {
  for (const Body& b : model.bodies) {
    if (!b.joint.prescribed()) {  // a prescribed joint has no q
      const JointTraits& t = joint_traits(b.joint.type);
      S qj[kMaxJointCoordinates], uj[kMaxJointSpeeds], qdj[kMaxJointCoordinates];
      for (int k = 0; k < t.nq(); ++k) qj[k] = S(q(b.q_joint + k));
      for (int k = 0; k < t.nu(); ++k) uj[k] = S(u(b.u_joint + k));
      joints::joint_qdot<S>(b.primitives, qj, uj, qdj);
      for (int k = 0; k < t.nq(); ++k) qdot(b.q_joint + k) = qdj[k];
    }
    for (int k = 0; k < b.n_modes(); ++k) qdot(b.q_eta + k) = S(u(b.u_eta + k));
  }
}

}  // namespace kanegen
