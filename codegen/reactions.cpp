// Joint reactions a posteriori (dynamics/reactions.hpp): body accelerations
// delta_j + z_R from u_dot, each body's wrench M_body z_dot + h - g, summed
// from the leaves to the root through Xe^T.
#include <fmt/format.h>

#include "codegen/kane_context.hpp"

namespace kanegen::codegen {

using namespace GiNaC;

std::vector<ex> compute_reactions(KaneContext& ctx, const std::vector<ex>& udot,
                                  std::vector<std::vector<ex>>* accelerations) {
  const int nb = static_cast<int>(ctx.model.bodies.size());
  // delta_j = acceleration minus remainder: delta_c = Xe_c delta_p + S_c udot_own
  std::vector<std::vector<ex>> delta(nb), W(nb);
  for (int j = 0; j < nb; ++j) {
    const Body& b = ctx.model.bodies[j];
    const SymBodyWorkspace& s = ctx.body[j];
    const int m = b.n_modes();
    std::vector<ex> dl = transform_motion_from_parent(ctx, j, b.parent >= 0 ? &delta[b.parent] : nullptr);
    const auto S = motion_subspace(ctx, j);
    const auto cols = own_columns(ctx.model, j);
    for (std::size_t k = 0; k < cols.size(); ++k)
      for (int r = 0; r < 6 + m; ++r) dl[r] = dl[r] + S[k][r] * udot[cols[k]];
    for (auto& e : dl) e = ctx.A.let(e);
    delta[j] = dl;
    // wrench = M_b (delta + z_R) + h - g - (the inputs' wrench), rows 0-5
    W[j].resize(6);
    const std::vector<ex> W_in = ctx.model.inputs.empty() ? std::vector<ex>(6, ex(0)) : input_wrench(ctx, j);
    if (accelerations) {
      std::vector<ex> z(dl);
      for (int k = 0; k < 3; ++k) z[k] = ctx.A.let(z[k] + s.a_R_B[k]);
      for (int k = 0; k < 3; ++k) z[3 + k] = ctx.A.let(z[3 + k] + s.alpha_R_B[k]);
      accelerations->push_back(z);
    }
    for (int r = 0; r < 6; ++r) {
      ex sum = s.h_body[r] - s.g_body[r] - W_in[r];
      for (int k = 0; k < 6 + m; ++k) {
        ex z = dl[k];
        if (k < 3) z = z + s.a_R_B[k];
        else if (k < 6) z = z + s.alpha_R_B[k - 3];
        sum += s.M_body(r, k) * z;
      }
      W[j][r] = ctx.A.let(sum);
    }
  }
  for (int j = nb - 1; j >= 0; --j) {
    const int p = ctx.model.bodies[j].parent;
    if (p < 0) continue;
    const auto Wp = transform_wrench_to_parent(ctx, j, W[j]);
    for (int r = 0; r < 6; ++r) W[p][r] = ctx.A.let(W[p][r] + Wp[r]);
  }
  std::vector<ex> out;
  for (int j = 0; j < nb; ++j) out.insert(out.end(), W[j].begin(), W[j].end());
  return out;
}

}  // namespace kanegen::codegen
