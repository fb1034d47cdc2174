// M by composite inertias: Icj = M_body_j + Sum_children Xe^T Icc Xe (leaves
// first), then each own column f = Icj S walked to the root through Xe^T:
// O(n d) entries, and the entries between different kinematic chains stay
// exactly zero. Equals Sum_j P_j^T M_body_j P_j (dynamics/mass_matrix.hpp).
#include <fmt/format.h>

#include "codegen/kane_context.hpp"

namespace kanegen::codegen {

using namespace GiNaC;

SMat compute_mass_matrix(KaneContext& ctx) {
  const int nb = static_cast<int>(ctx.model.bodies.size());
  const int nu = ctx.model.nu;
  SMat M(nu, nu);
  // Composite inertias, leaves first.
  std::vector<SMat> Ic(nb);
  for (int j = 0; j < nb; ++j) Ic[j] = ctx.body[j].M_body;
  for (int j = nb - 1; j >= 0; --j) {
    const int p = ctx.model.bodies[j].parent;
    ctx.P.section(fmt::format("body {}: composite inertia (inward)", ctx.model.bodies[j].name));
    SMat& I = Ic[j];
    for (auto& e : I.a) e = ctx.A.let(e);
    if (p < 0) continue;
    const SymBodyWorkspace& s = ctx.body[j];
    // Rigid form [m, -S^x; S^x, J]: m' = m, S' = R S + m d, J' = R J R^T - d^x S'^x... done as
    // a turn by R_JB, a shift by d = O_B - O_P in J components, and a turn by R_PJ (then R_PS).
    const ex mass = I(0, 0);
    const SV3 S{{I(5, 1), I(3, 2), I(4, 0)}};  // from I(3..5, 0..2) = S^x
    SM3 J;
    for (int a = 0; a < 3; ++a)
      for (int cc = 0; cc < 3; ++cc) J(a, cc) = I(3 + a, 3 + cc);
    const SV3 S1 = ctx.A.mul(s.R_JB, S);
    const SM3 J1 = rotate_symmetric(ctx, s.R_JB, J);
    // J2 = J1 - d^x S1^x - S1^x d^x - m d^x d^x, S2 = S1 + m d (J components)
    const SM3 dx = Alg::skew(s.p_BP_J), S1x = Alg::skew(S1);
    SM3 J2;
    for (int a = 0; a < 3; ++a)
      for (int cc = a; cc < 3; ++cc) {
        ex sum = J1(a, cc);
        for (int t = 0; t < 3; ++t) sum -= dx(a, t) * S1x(t, cc) + S1x(a, t) * dx(t, cc) + mass * dx(a, t) * dx(t, cc);
        J2(a, cc) = J2(cc, a) = ctx.A.let(sum);
      }
    SV3 Sp = ctx.A.mul(s.R_PJ, ctx.A.add(S1, ctx.A.scale(mass, s.p_BP_J)));
    SM3 Jp = rotate_symmetric(ctx, s.R_PJ, J2);
    if (s.screw) Sp = ctx.A.mul(s.R_PS, Sp), Jp = rotate_symmetric(ctx, s.R_PS, Jp);
    SMat& Ip = Ic[p];
    for (int a = 0; a < 3; ++a)
      for (int cc = a; cc < 3; ++cc) {
        const ex v = ctx.A.let(Ip(3 + a, 3 + cc) + Jp(a, cc));
        Ip(3 + a, 3 + cc) = v;
        Ip(3 + cc, 3 + a) = v;
      }
    for (int a = 0; a < 3; ++a) Ip(a, a) = ctx.A.let(Ip(a, a) + mass);
    const SM3 Spx = Alg::skew(Sp);
    for (int a = 0; a < 3; ++a)
      for (int cc = 0; cc < 3; ++cc) {
        if (Spx(a, cc).is_zero()) continue;
        Ip(3 + a, cc) = ctx.A.let(Ip(3 + a, cc) + Spx(a, cc));
        Ip(cc, 3 + a) = ctx.A.let(Ip(cc, 3 + a) + Spx(a, cc));
      }
    // Node coupling of a child at a node of a flexible parent: with
    // Xe = [X6 | N], add X6^T I6 N (6 x m_p) and N^T I6 N (m_p x m_p).
    const int m_P = static_cast<int>(s.P_node.size());
    if (m_P > 0) {
      std::vector<std::vector<ex>> I6N(m_P);  // I6 * N_i
      for (int i = 0; i < m_P; ++i) {
        I6N[i].resize(6);
        for (int r = 0; r < 6; ++r) {
          ex sum = 0;
          for (int k = 0; k < 6; ++k) sum += I(r, k) * s.P_node[i][k];
          I6N[i][r] = ctx.A.let(sum);
        }
      }
      for (int i = 0; i < m_P; ++i) {
        const auto top = transform_wrench_to_parent(ctx, j, I6N[i]);  // X6^T (I6 N_i), plus N^T I6 N_i below
        for (int r = 0; r < 6; ++r) {
          Ip(r, 6 + i) = ctx.A.let(Ip(r, 6 + i) + top[r]);
          Ip(6 + i, r) = Ip(r, 6 + i);
        }
        for (int k = 0; k < m_P; ++k) Ip(6 + k, 6 + i) = ctx.A.let(Ip(6 + k, 6 + i) + top[6 + k]);
      }
    }
  }
  // Columns: f = Icj S_j[:, s]; M(own_j, s) = S_j^T f; then walk to the root.
  for (int j = 0; j < nb; ++j) {
    ctx.P.section(fmt::format("body {}: its columns of M (walked to the root)", ctx.model.bodies[j].name));
    const auto S = motion_subspace(ctx, j);
    const auto cols = own_columns(ctx.model, j);
    const SMat& I = Ic[j];
    for (std::size_t k = 0; k < cols.size(); ++k) {
      std::vector<ex> f(I.rows);
      for (int r = 0; r < I.rows; ++r) {
        ex sum = 0;
        for (int cc = 0; cc < I.cols; ++cc) sum += I(r, cc) * S[k][cc];
        f[r] = ctx.A.let(sum);
      }
      for (std::size_t k2 = 0; k2 <= k; ++k2) {
        M(cols[k], cols[k2]) = M(cols[k2], cols[k]) = ctx.A.let(dot(S[k2], f));
      }
      int i = j;
      std::vector<ex> fi = f;
      while (ctx.model.bodies[i].parent >= 0) {
        const int p = ctx.model.bodies[i].parent;
        fi = transform_wrench_to_parent(ctx, i, {fi.begin(), fi.begin() + 6});
        const auto Sp = motion_subspace(ctx, p);
        const auto pcols = own_columns(ctx.model, p);
        for (std::size_t kp = 0; kp < pcols.size(); ++kp)
          M(pcols[kp], cols[k]) = M(cols[k], pcols[kp]) = ctx.A.let(dot(Sp[kp], fi));
        i = p;
      }
    }
  }
  return M;
}

}  // namespace kanegen::codegen
