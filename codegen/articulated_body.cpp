// u_dot by the articulated-body recursion (Featherstone), O(n): inward
// articulated inertias IA_j and bias wrenches pA_j through Xe^T, outward
// accelerations. Chosen over the composite form by operation count.
#include <fmt/format.h>

#include "codegen/kane_context.hpp"

namespace kanegen::codegen {

using namespace GiNaC;

/// Inverse of a small symmetric positive-definite matrix by L D L^T; D_ii in `pivots`.
static SMat spd_inverse(KaneContext& ctx, const SMat& D, std::vector<ex>& pivots) {
  const int k = D.rows;
  // L D L^T, then inverse = L^-T Dg^-1 L^-1
  SMat L(k, k);
  std::vector<ex> Dg(k);
  for (int i = 0; i < k; ++i) {
    ex d = D(i, i);
    for (int t = 0; t < i; ++t) d -= L(i, t) * L(i, t) * Dg[t];
    Dg[i] = ctx.A.let(d);
    pivots.push_back(Dg[i]);
    L(i, i) = 1;
    const ex inv = ctx.A.let(1 / Dg[i]);
    for (int r = i + 1; r < k; ++r) {
      ex v = D(r, i);
      for (int t = 0; t < i; ++t) v -= L(r, t) * L(i, t) * Dg[t];
      L(r, i) = ctx.A.let(v * inv);
    }
  }
  // Linv (unit lower)
  SMat Li(k, k);
  for (int c = 0; c < k; ++c) {
    Li(c, c) = 1;
    for (int r = c + 1; r < k; ++r) {
      ex v = 0;
      for (int t = c; t < r; ++t) v -= L(r, t) * Li(t, c);
      Li(r, c) = ctx.A.let(v);
    }
  }
  SMat inv(k, k);
  for (int r = 0; r < k; ++r)
    for (int c = r; c < k; ++c) {
      ex v = 0;
      for (int t = std::max(r, c); t < k; ++t) v += Li(t, r) * Li(t, c) / Dg[t];
      inv(r, c) = inv(c, r) = ctx.A.let(v);
    }
  return inv;
}

// Articulated-body form, O(n): with delta_j = body accelerations minus their
// remainders (delta_j = Xe_j delta_p + S_j udot_j), the subtree wrench of j is
// IA_j delta_j + pA_j. Inward: U = IA S, D = S^T U, r = tau' - S^T pA,
// Ia = IA - U D^-1 U^T, pa = pA + U D^-1 r, passed to the parent through
// Xe^T; outward: udot_j = D^-1 (r - U^T Xe_j delta_p).
std::vector<ex> compute_udot_articulated(KaneContext& ctx, std::vector<ex>& pivots, std::vector<ex>& pivot_scales) {
  const int nb = static_cast<int>(ctx.model.bodies.size());
  std::vector<std::vector<ex>> pA = compute_bias_forces(ctx);
  for (auto& v : pA)
    for (auto& e : v) e = ctx.A.let(-e);
  std::vector<SMat> IA(nb);
  for (int j = 0; j < nb; ++j) IA[j] = ctx.body[j].M_body;
  struct Joint {
    std::vector<std::vector<ex>> U;   // (6+m) x k, by column
    SMat Dinv;                        // k x k
    std::vector<ex> r;                // k
  };
  std::vector<Joint> J(nb);
  pivots.assign(ctx.model.nu, ex(1));  // by speed; bodies are visited leaves first
  pivot_scales.assign(ctx.model.nu, ex(0));
  for (int j = nb - 1; j >= 0; --j) {
    const Body& b = ctx.model.bodies[j];
    ctx.P.section(fmt::format("body {}: articulated inertia and bias force (inward)", b.name));
    const auto S = motion_subspace(ctx, j);
    const int k = static_cast<int>(S.size());
    const int n = IA[j].rows;
    SMat& I = IA[j];
    for (auto& e : I.a) e = ctx.A.let(e);
    Joint& jt = J[j];
    jt.U.assign(k, std::vector<ex>(n));
    for (int c = 0; c < k; ++c)
      for (int r = 0; r < n; ++r) {
        ex sum = 0;
        for (int t = 0; t < n; ++t) sum += I(r, t) * S[c][t];
        jt.U[c][r] = ctx.A.let(sum);
      }
    SMat D(k, k);
    jt.r.resize(k);
    for (int c = 0; c < k; ++c) {
      for (int c2 = 0; c2 <= c; ++c2) D(c, c2) = D(c2, c) = ctx.A.let(dot(S[c2], jt.U[c]));
      jt.r[c] = ctx.A.let(applied_force(ctx, j, c) - dot(S[c], pA[j]));
    }
    std::vector<ex> joint_pivots;
    jt.Dinv = spd_inverse(ctx, D, joint_pivots);
    const auto own = own_columns(ctx.model, j);
    for (int c = 0; c < k; ++c) {
      pivots[own[c]] = joint_pivots[c];
      // scale: the trace of the 3x3 block of I^A the column moves (same units
      // as the pivot); modal columns are judged against 0
      for (int blk = 0; blk < 2; ++blk) {
        bool moves = false;
        for (int r = 3 * blk; r < 3 * blk + 3; ++r) moves = moves || !S[c][r].is_zero();
        if (moves && pivot_scales[own[c]].is_zero())
          pivot_scales[own[c]] = ctx.A.let(I(3 * blk, 3 * blk) + I(3 * blk + 1, 3 * blk + 1) + I(3 * blk + 2, 3 * blk + 2));
      }
      if (pivot_scales[own[c]].is_zero()) pivot_scales[own[c]] = joint_pivots[c];
    }
    if (b.parent < 0) continue;
    // Ia = IA - U Dinv U^T (rows/cols 0-5 are all the parent sees), pa = pA + U Dinv r
    std::vector<std::vector<ex>> UD(k, std::vector<ex>(6));  // (U Dinv) by column, rows 0-5
    for (int c = 0; c < k; ++c)
      for (int r = 0; r < 6; ++r) {
        ex sum = 0;
        for (int t = 0; t < k; ++t) sum += jt.U[t][r] * jt.Dinv(t, c);
        UD[c][r] = ctx.A.let(sum);
      }
    SMat Ia(6, 6);
    std::vector<ex> pa(6);
    // A joint whose one column is a coordinate vector e_k (the generator's
    // frames make revolute and prismatic joints so): Ia e_k = U - U D^-1 D = 0
    // exactly, so row and column k of Ia are zero.
    int unit_col = -1;
    if (k == 1) {
      int nonzero = 0;
      for (int r = 0; r < 6; ++r)
        if (!S[0][r].is_zero()) ++nonzero, unit_col = r;
      for (int r = 6; r < n; ++r)
        if (!S[0][r].is_zero()) nonzero = 2;
      if (nonzero != 1 || !(S[0][unit_col] - 1).is_zero()) unit_col = -1;
    }
    for (int r = 0; r < 6; ++r) {
      for (int c = r; c < 6; ++c) {
        if (r == unit_col || c == unit_col) {
          Ia(r, c) = Ia(c, r) = 0;
          continue;
        }
        ex sum = I(r, c);
        for (int t = 0; t < k; ++t) sum -= UD[t][r] * jt.U[t][c];
        Ia(r, c) = Ia(c, r) = ctx.A.let(sum);
      }
      ex sum = pA[j][r];
      for (int t = 0; t < k; ++t) sum += UD[t][r] * jt.r[t];
      pa[r] = ctx.A.let(sum);
    }
    // Parent: IA_p += Xe^T Ia Xe, pA_p += Xe^T pa, Xe = [X6 | N] acting on the parent's (6 + m_p).
    const int np = IA[b.parent].rows;
    if (ctx.body[j].P_node.empty()) {  // the 6 x 6 block formula (spatial_transforms.cpp)
      const SMat T = transform_inertia_to_parent(ctx, j, Ia);
      for (int a = 0; a < 6; ++a)
        for (int bb = a; bb < 6; ++bb) {
          const ex v = ctx.A.let(IA[b.parent](a, bb) + T(a, bb));
          IA[b.parent](a, bb) = IA[b.parent](bb, a) = v;
        }
      const auto pt = transform_wrench_to_parent(ctx, j, pa);
      for (int r = 0; r < np; ++r) pA[b.parent][r] = ctx.A.let(pA[b.parent][r] + pt[r]);
      continue;
    }
    std::vector<std::vector<ex>> XtIa(6);  // XtIa[c] = Xe^T Ia[:, c]  (np entries)
    for (int c = 0; c < 6; ++c) {
      std::vector<ex> col(6);
      for (int r = 0; r < 6; ++r) col[r] = Ia(r, c);
      XtIa[c] = transform_wrench_to_parent(ctx, j, col);
    }
    // Xe^T Ia Xe = Xe^T (Xe^T Ia)^T: row a of (Xe^T Ia) is the np-vector over c -> XtIa[c][a]
    for (int a = 0; a < np; ++a) {
      std::vector<ex> row(6);
      for (int c = 0; c < 6; ++c) row[c] = XtIa[c][a];
      const auto t = transform_wrench_to_parent(ctx, j, row);
      for (int bb = a; bb < np; ++bb) {
        const ex v = ctx.A.let(IA[b.parent](a, bb) + t[bb]);
        IA[b.parent](a, bb) = IA[b.parent](bb, a) = v;
      }
    }
    const auto pt = transform_wrench_to_parent(ctx, j, pa);
    for (int r = 0; r < np; ++r) pA[b.parent][r] = ctx.A.let(pA[b.parent][r] + pt[r]);
  }
  // Outward.
  std::vector<ex> ud(ctx.model.nu, ex(0));
  std::vector<std::vector<ex>> delta(nb);
  for (int j = 0; j < nb; ++j) {
    const Body& b = ctx.model.bodies[j];
    ctx.P.section(fmt::format("body {}: accelerations (outward)", b.name));
    const int n = IA[j].rows;
    std::vector<ex> dl = transform_motion_from_parent(ctx, j, b.parent >= 0 ? &delta[b.parent] : nullptr);
    const auto S = motion_subspace(ctx, j);
    const int k = static_cast<int>(S.size());
    const Joint& jt = J[j];
    std::vector<ex> rhs(k);
    for (int c = 0; c < k; ++c) rhs[c] = ctx.A.let(jt.r[c] - dot(jt.U[c], dl));
    const auto cols = own_columns(ctx.model, j);
    for (int c = 0; c < k; ++c) {
      ex sum = 0;
      for (int t = 0; t < k; ++t) sum += jt.Dinv(c, t) * rhs[t];
      ud[cols[c]] = ctx.A.let(sum);
    }
    for (int c = 0; c < k; ++c)
      for (int r = 0; r < n; ++r) dl[r] = dl[r] + S[c][r] * ud[cols[c]];
    for (auto& e : dl) e = ctx.A.let(e);
    delta[j] = dl;
  }
  return ud;
}

}  // namespace kanegen::codegen
