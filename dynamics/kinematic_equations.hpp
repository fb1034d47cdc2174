// q_dot = W(q) u (dynamics.md joint table): identity for revolute, prismatic
// and modal coordinates; for a free joint [x y z]_dot = R(quat) v and
// quat_dot = 1/2 quat (x) [0, w], with the quaternion used as given (its norm
// is then preserved exactly by the flow; the engines normalize it for M, F).
#pragma once

#include "model/model.hpp"
#include "model/rotation.hpp"

namespace kanegen {

template <class S, class VecQ, class VecU, class VecQd>
void compute_qdot(const Model& model, const VecQ& q, const VecU& u, VecQd& qdot) {
  for (const Body& b : model.bodies) {
    switch (b.joint.prescribed() ? JointType::fixed : b.joint.type) {  // a prescribed joint has no q
      case JointType::revolute:
      case JointType::prismatic: qdot(b.q_joint) = S(u(b.u_joint)); break;
      case JointType::fixed: break;
      case JointType::free: {
        const V4<S> quat(S(q(b.q_joint + 3)), S(q(b.q_joint + 4)), S(q(b.q_joint + 5)), S(q(b.q_joint + 6)));
        const V3<S> v(S(u(b.u_joint)), S(u(b.u_joint + 1)), S(u(b.u_joint + 2)));
        const V4<S> w(S(0), S(u(b.u_joint + 3)), S(u(b.u_joint + 4)), S(u(b.u_joint + 5)));
        using std::sqrt;
        const V3<S> xyz_dot = quat_to_R<S>(V4<S>(quat / sqrt(quat.dot(quat)))) * v;
        const V4<S> quat_dot = quat_mul<S>(quat, w) / S(2);
        for (int k = 0; k < 3; ++k) qdot(b.q_joint + k) = xyz_dot(k);
        for (int k = 0; k < 4; ++k) qdot(b.q_joint + 3 + k) = quat_dot(k);
        break;
      }
    }
    for (int k = 0; k < b.n_modes(); ++k) qdot(b.q_eta + k) = S(u(b.u_eta + k));
  }
}

}  // namespace kanegen
