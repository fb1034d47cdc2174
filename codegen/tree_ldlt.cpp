// M x = b by the L^T D L factorization along the dof tree (Featherstone's
// LTDL with the parent array lambda of the speeds): a speed's row only
// touches its ancestors, so the zero blocks between kinematic chains cause no
// fill-in.
#include <fmt/format.h>

#include "codegen/kane_context.hpp"

namespace kanegen::codegen {

using namespace GiNaC;

std::vector<ex> solve_tree_ldlt(KaneContext& ctx, SMat H, std::vector<ex> b, std::vector<ex>& pivots,
                                std::vector<ex>& pivot_scales) {
  const int n = H.rows;
  // lambda: parent of each dof in the dof tree
  std::vector<int> lambda(n, -1);
  for (const Body& bd : ctx.model.bodies) {
    const int nown = joint_nu(bd.joint) + bd.n_modes();
    if (nown == 0) continue;
    int prev = -1;
    if (bd.parent >= 0) {
      const auto& ch = ctx.model.bodies[bd.parent].chain_u;
      prev = ch.empty() ? -1 : ch.back();
    }
    for (int k = 0; k < nown; ++k) {
      lambda[bd.u_joint + k] = prev;
      prev = bd.u_joint + k;
    }
  }
  ctx.P.section("M u_dot = F: L^T D L along the dof tree");
  std::vector<ex> diagonal(n);
  for (int k = 0; k < n; ++k) diagonal[k] = H(k, k);
  for (int k = n - 1; k >= 0; --k) {
    int i = lambda[k];
    const ex inv = ctx.A.let(1 / H(k, k));
    while (i != -1) {
      const ex a = ctx.A.let(H(k, i) * inv);
      int jj = i;
      while (jj != -1) {
        H(i, jj) = ctx.A.let(H(i, jj) - a * H(k, jj));
        jj = lambda[jj];
      }
      H(k, i) = a;
      i = lambda[i];
    }
  }
  pivots.resize(n);
  for (int k = 0; k < n; ++k) pivots[k] = H(k, k);
  pivot_scales = diagonal;
  for (int i = n - 1; i >= 0; --i)
    for (int jj = lambda[i]; jj != -1; jj = lambda[jj]) b[jj] = ctx.A.let(b[jj] - H(i, jj) * b[i]);
  for (int i = 0; i < n; ++i) b[i] = ctx.A.let(b[i] / H(i, i));
  for (int i = 0; i < n; ++i)
    for (int jj = lambda[i]; jj != -1; jj = lambda[jj]) b[i] = ctx.A.let(b[i] - H(i, jj) * b[jj]);
  return b;
}

}  // namespace kanegen::codegen
