// Motion subspaces S_j and the transforms between a body and its parent
// (Xe_j: the partial-velocity recursion P_child = Xe P_parent + S), the bias
// forces and the applied generalized forces that every symbolic pass shares.
#include <fmt/format.h>

#include "codegen/kane_context.hpp"

namespace kanegen::codegen {

using namespace GiNaC;

std::vector<int> own_columns(const Model& model, int j) {
  const Body& b = model.bodies[j];
  std::vector<int> cols;
  for (int k = 0; k < joint_nu(b.joint) + b.n_modes(); ++k) cols.push_back(b.u_joint + k);
  return cols;
}

std::vector<std::vector<ex>> motion_subspace(KaneContext& ctx, int j) {
  const Body& b = ctx.model.bodies[j];
  const int m = b.n_modes();
  std::vector<std::vector<ex>> S;
  ctx.C.group = b.name;
  const SV3 axis = ctx.cvec(b.joint.axis_J, b.name + "_axis", "", "joint axis");
  switch (b.joint.prescribed() ? JointType::fixed : b.joint.type) {  // a prescribed joint has no column
    case JointType::revolute: {
      std::vector<ex> col(6 + m, ex(0));
      for (int a = 0; a < 3; ++a) col[3 + a] = axis[a];
      S.push_back(col);
      break;
    }
    case JointType::prismatic: {
      std::vector<ex> col(6 + m, ex(0));
      for (int a = 0; a < 3; ++a) col[a] = axis[a];
      S.push_back(col);
      break;
    }
    case JointType::fixed: break;
    case JointType::free:
      for (int c = 0; c < 6; ++c) {
        std::vector<ex> col(6 + m, ex(0));
        col[c] = 1;
        S.push_back(col);
      }
      break;
  }
  for (int i = 0; i < m; ++i) {
    std::vector<ex> col(6 + m, ex(0));
    col[6 + i] = 1;
    S.push_back(col);
  }
  return S;
}

std::vector<ex> transform_motion_from_parent(KaneContext& ctx, int j, const std::vector<ex>* dp) {
  const SymBodyWorkspace& s = ctx.body[j];
  std::vector<ex> dl(6 + ctx.model.bodies[j].n_modes(), ex(0));
  if (!dp) return dl;
  const SM3 R_BP = s.R_PB.transpose();
  const SV3 ap{{(*dp)[0], (*dp)[1], (*dp)[2]}}, alp{{(*dp)[3], (*dp)[4], (*dp)[5]}};
  const SV3 lin = ctx.A.mul(R_BP, ctx.A.add(ap, ctx.A.cross(alp, s.p_PO_P)));
  const SV3 ang = ctx.A.mul(R_BP, alp);
  for (int a = 0; a < 3; ++a) dl[a] = lin[a], dl[3 + a] = ang[a];
  for (int i = 0; i < static_cast<int>(s.P_node.size()); ++i)
    for (int r = 0; r < 6; ++r) dl[r] = dl[r] + s.P_node[i][r] * (*dp)[6 + i];
  return dl;
}

std::vector<ex> transform_wrench_to_parent(KaneContext& ctx, int cidx, const std::vector<ex>& W6) {
  const SymBodyWorkspace& s = ctx.body[cidx];
  const int p = ctx.model.bodies[cidx].parent;
  const int m_P = ctx.model.bodies[p].n_modes();
  const SV3 f{{W6[0], W6[1], W6[2]}}, t{{W6[3], W6[4], W6[5]}};
  const SV3 fP = ctx.A.mul(s.R_PB, f);
  const SV3 tP = ctx.A.add(ctx.A.mul(s.R_PB, t), ctx.A.cross(s.p_PO_P, fP));
  std::vector<ex> out(6 + m_P, ex(0));
  for (int a = 0; a < 3; ++a) out[a] = fP[a], out[3 + a] = tP[a];
  for (int i = 0; i < static_cast<int>(s.P_node.size()); ++i) {
    ex sum = 0;
    for (int r = 0; r < 6; ++r) sum += s.P_node[i][r] * W6[r];
    out[6 + i] = ctx.A.let(sum);
  }
  return out;
}

std::vector<std::vector<ex>> compute_bias_forces(KaneContext& ctx) {
  const int nb = static_cast<int>(ctx.model.bodies.size());
  std::vector<std::vector<ex>> y(nb);
  for (int j = 0; j < nb; ++j) {  // y_j = g_j - h_j - M_j z_R
    const SymBodyWorkspace& s = ctx.body[j];
    const int n = 6 + ctx.model.bodies[j].n_modes();
    y[j].resize(n);
    for (int r = 0; r < n; ++r) {
      ex sum = s.g_body[r] - s.h_body[r];
      for (int a = 0; a < 3; ++a) sum -= s.M_body(r, a) * s.a_R_B[a] + s.M_body(r, 3 + a) * s.alpha_R_B[a];
      y[j][r] = ctx.A.let(sum);
    }
  }
  return y;
}

ex applied_force(KaneContext& ctx, int j, int own) {
  const Body& b = ctx.model.bodies[j];
  const int r = b.u_joint + own;
  ex f = ctx.x.tau[r];
  ctx.C.group = b.name;
  if (own < joint_nu(b.joint) && (b.joint.type == JointType::revolute || b.joint.type == JointType::prismatic)) {
    const ex kk = ctx.c(b.joint.stiffness, b.name + "_k", "N m/rad or N/m", "joint spring stiffness");
    const ex cc = ctx.c(b.joint.damping, b.name + "_c", "N m s/rad or N s/m", "joint damping");
    const ex rest = ctx.c(b.joint.rest, b.name + "_rest", "rad or m", "spring rest value");
    f -= kk * (ctx.x.q[b.q_joint] - rest) + cc * ctx.x.u[b.u_joint];
  }
  if (own >= joint_nu(b.joint)) {
    const int i = own - joint_nu(b.joint);
    const ex K = ctx.c(b.flex->K(i), fmt::format("{}_K{}", b.name, i + 1), "N m", "modal stiffness");
    const ex D = ctx.c(b.flex->D(i), fmt::format("{}_D{}", b.name, i + 1), "N m s", "modal damping");
    f -= K * ctx.x.q[b.q_eta + i] + D * ctx.x.u[b.u_eta + i];
  }
  return ctx.A.let(f);
}

}  // namespace kanegen::codegen
