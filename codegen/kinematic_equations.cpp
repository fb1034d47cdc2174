// q_dot = W(q) u (dynamics/kinematic_equations.hpp).
#include <fmt/format.h>

#include "codegen/kane_context.hpp"
#include "model/joints/joint_kinematics.hpp"

namespace kanegen::codegen {

using namespace GiNaC;

std::vector<ex> compute_qdot(KaneContext& ctx) {
  std::vector<ex> qd(ctx.model.nq, ex(0));
  for (const Body& b : ctx.model.bodies) {
    switch (b.joint.prescribed() ? JointType::fixed : b.joint.type) {  // a prescribed joint has no q
      case JointType::revolute:
      case JointType::prismatic: qd[b.q_joint] = ctx.x.u[b.u_joint]; break;
      case JointType::fixed: break;
      case JointType::free: {
        const int q0 = b.q_joint, u0 = b.u_joint;
        const ex w = ctx.x.q[q0 + 3], xq = ctx.x.q[q0 + 4], y = ctx.x.q[q0 + 5], z = ctx.x.q[q0 + 6];
        const ex inv2 = ctx.A.let(1 / (w * w + xq * xq + y * y + z * z));
        // R(quat/|quat|) v: the quadratic form of R divided by |quat|^2
        SM3 R;
        R(0, 0) = w * w + xq * xq - y * y - z * z, R(0, 1) = 2 * (xq * y - w * z), R(0, 2) = 2 * (xq * z + w * y);
        R(1, 0) = 2 * (xq * y + w * z), R(1, 1) = w * w - xq * xq + y * y - z * z, R(1, 2) = 2 * (y * z - w * xq);
        R(2, 0) = 2 * (xq * z - w * y), R(2, 1) = 2 * (y * z + w * xq), R(2, 2) = w * w - xq * xq - y * y + z * z;
        for (int r = 0; r < 3; ++r) {
          ex sum = 0;
          for (int k = 0; k < 3; ++k) sum += ctx.A.let(R(r, k)) * ctx.x.u[u0 + k];
          qd[q0 + r] = ctx.A.let(sum * inv2);
        }
        const ex wx = ctx.x.u[u0 + 3], wy = ctx.x.u[u0 + 4], wz = ctx.x.u[u0 + 5];
        qd[q0 + 3] = ctx.A.let((-xq * wx - y * wy - z * wz) / 2);
        qd[q0 + 4] = ctx.A.let((w * wx + y * wz - z * wy) / 2);
        qd[q0 + 5] = ctx.A.let((w * wy - xq * wz + z * wx) / 2);
        qd[q0 + 6] = ctx.A.let((w * wz + xq * wy - y * wx) / 2);
        break;
      }
      default: {  // the joint module's q_dot (model/joints/joint_kinematics.hpp)
        const JointTraits& jt = joint_traits(b.joint.type);
        std::vector<ex> qj(jt.nq()), uj(jt.nu()), qdj(jt.nq());
        for (int k = 0; k < jt.nq(); ++k) qj[k] = ctx.x.q[b.q_joint + k];
        for (int k = 0; k < jt.nu(); ++k) uj[k] = ctx.x.u[b.u_joint + k];
        joints::joint_qdot<ex>(b.primitives, qj.data(), uj.data(), qdj.data());
        for (int k = 0; k < jt.nq(); ++k) qd[b.q_joint + k] = ctx.A.let(qdj[k]);
        break;
      }
    }
    for (int i = 0; i < b.n_modes(); ++i) qd[b.q_eta + i] = ctx.x.u[b.u_eta + i];
  }
  return qd;
}

}  // namespace kanegen::codegen
