// Joint reactions a posteriori (the paper's Newton-Euler post-processing):
// with q, u and u-dot known, each body's accelerations are z_dot = P u_dot + z_R,
// and the wrench its own mass elements need is M_body z_dot + h_body - g_body
// (rows 0-5: force and torque about O_B, B components). Summing these from the
// ends of the kinematic chains back to the root, each child's subtree wrench
// shifted to the parent's origin, gives the wrench (f_j, t_j) that the parent
// exerts on body j across its joint (dynamics.md). Requires compute_kinematics
// and compute_body_terms.
#pragma once

#include "model/model.hpp"
#include "dynamics/applied_inputs.hpp"
#include "dynamics/workspace.hpp"

namespace kanegen {

/// `w`: the named inputs (their wrenches are applied, not transmitted by the joint).
template <class S, class VecUd, class VecW>
void compute_reactions(const Model& model, Workspace<S>& ws, const VecUd& udot, const VecW& w) {
  const int nb = static_cast<int>(model.bodies.size());
  for (int i = 0; i < nb; ++i) {
    const std::vector<int>& chain = model.bodies[i].chain_u;
    BodyWorkspace<S>& s = ws.body[i];
    s.z_dot.setZero();
    for (std::size_t c = 0; c < chain.size(); ++c) s.z_dot += s.P.col(c) * S(udot(chain[c]));
    s.z_dot.template head<3>() += s.a_R_B;
    s.z_dot.template segment<3>(3) += s.alpha_R_B;
    s.wrench_B = (s.M_body.template topRows<6>() * s.z_dot + s.h_body.template head<6>() -
                  s.g_body.template head<6>());
    for (const Input& in : model.inputs)
      if (in.body == i && in.type != InputType::joint_torque) {
        Eigen::Matrix<S, Eigen::Dynamic, 1> Y = Eigen::Matrix<S, Eigen::Dynamic, 1>::Zero(6 + model.bodies[i].n_modes());
        add_input_generalized_force(in, model.bodies[i], s, w, Y);
        s.wrench_B -= Y.template head<6>();
      }
  }
  for (int i = nb - 1; i >= 0; --i) {  // children are listed after their parents
    const int p = model.bodies[i].parent;
    if (p < 0) continue;
    const BodyWorkspace<S>& s = ws.body[i];
    const V3<S> f_P = s.R_PB * s.wrench_B.template head<3>();
    const V3<S> t_P = s.R_PB * s.wrench_B.template tail<3>() + s.p_PO_P.cross(f_P);
    ws.body[p].wrench_B.template head<3>() += f_P;
    ws.body[p].wrench_B.template tail<3>() += t_P;
  }
}

}  // namespace kanegen
