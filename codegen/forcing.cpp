// F = tau + elastic forces + S^T W by the inward pass, W_j = y_j + Sum_children
// Xe^T W_c (y_j: the bias forces of spatial_transforms.cpp); O(n). The generic
// engine forms the same sum as Sum_j P_j^T y_j (dynamics/forcing.hpp).
#include <fmt/format.h>

#include "codegen/kane_context.hpp"

namespace kanegen::codegen {

using namespace GiNaC;

std::vector<ex> compute_forcing(KaneContext& ctx) {
  const int nb = static_cast<int>(ctx.model.bodies.size());
  std::vector<std::vector<ex>> W = compute_bias_forces(ctx);
  std::vector<ex> F(ctx.model.nu, ex(0));
  for (int j = nb - 1; j >= 0; --j) {
    const Body& b = ctx.model.bodies[j];
    ctx.P.section(fmt::format("body {}: generalized forces (inward)", b.name));
    const auto S = motion_subspace(ctx, j);
    const auto cols = own_columns(ctx.model, j);
    for (std::size_t k = 0; k < cols.size(); ++k) F[cols[k]] = ctx.A.let(applied_force(ctx, j, static_cast<int>(k)) + dot(S[k], W[j]));
    if (b.parent >= 0) {
      const auto Wp = transform_wrench_to_parent(ctx, j, {W[j].begin(), W[j].begin() + 6});
      for (std::size_t r = 0; r < Wp.size(); ++r) W[b.parent][r] = ctx.A.let(W[b.parent][r] + Wp[r]);
    }
  }
  return F;
}

}  // namespace kanegen::codegen
