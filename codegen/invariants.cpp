// Energy and momentum (dynamics/invariants.hpp): T = 1/2 Sum z^T M_body z;
// V = gravity (uniform or central) + springs + modal strain energy; p_N, H_N about N's origin
// from the first six rows of M_body z.
#include <fmt/format.h>

#include "codegen/kane_context.hpp"

namespace kanegen::codegen {

using namespace GiNaC;

SV3 first_moment_B(const SymBodyWorkspace& s) { return {{s.M_body(5, 1), s.M_body(3, 2), s.M_body(4, 0)}}; }

ex compute_kinetic_energy(KaneContext& ctx) {
  ex T = 0;
  for (std::size_t j = 0; j < ctx.model.bodies.size(); ++j) {
    const SymBodyWorkspace& s = ctx.body[j];
    const int n = s.M_body.rows;
    std::vector<ex> z(n);
    for (int a = 0; a < 3; ++a) z[a] = s.v_O_B[a], z[3 + a] = s.w_B[a];
    for (int i = 0; i + 6 < n; ++i) z[6 + i] = s.eta_dot[i];
    ex Tj = 0;
    for (int r = 0; r < n; ++r) {
      ex row = 0;
      for (int k = 0; k < n; ++k) row += s.M_body(r, k) * z[k];
      Tj += z[r] * ctx.A.let(row);
    }
    T += ctx.A.let(Tj);
  }
  return ctx.A.let(T / 2);
}

ex compute_potential_energy(KaneContext& ctx) {
  ex V = 0;
  ctx.C.group = "model";
  const SV3 g_N = ctx.gravity(1.0, "gravity", "gravity in N");
  for (std::size_t j = 0; j < ctx.model.bodies.size(); ++j) {
    const Body& b = ctx.model.bodies[j];
    const SymBodyWorkspace& s = ctx.body[j];
    if (ctx.has_gravity()) {
      // -g . (m r_O + R_NB S)
      const SV3 RS = ctx.A.mul(s.R_NB, first_moment_B(s));
      for (int a = 0; a < 3; ++a) V -= g_N[a] * (s.M_body(0, 0) * s.r_NO_N[a] + RS[a]);
    }
    if (ctx.has_central()) V += central_potential(ctx, static_cast<int>(j));
    ctx.C.group = b.name;
    for (const SpringSlot& sl : spring_slots(b.joint)) {
      if (sl.q < 0) continue;
      const auto [kk, cc_unused, rest] = joint_spring(ctx, static_cast<int>(j), sl.value);
      (void)cc_unused;
      const ex dq = ctx.A.let(ctx.x.q[b.q_joint + sl.q] - rest);
      V += kk * dq * dq / 2;
    }
    for (int i = 0; i < b.n_modes(); ++i) {
      const ex K = modal_stiffness_damping(ctx, static_cast<int>(j), i)[0];
      V += K * s.eta[i] * s.eta[i] / 2;
    }
    V = ctx.A.let(V);
  }
  return V;
}

std::vector<ex> compute_momentum(KaneContext& ctx) {
  SV3 p, H;
  for (std::size_t j = 0; j < ctx.model.bodies.size(); ++j) {
    const SymBodyWorkspace& s = ctx.body[j];
    const int n = s.M_body.rows;
    std::vector<ex> z(n);
    for (int a = 0; a < 3; ++a) z[a] = s.v_O_B[a], z[3 + a] = s.w_B[a];
    for (int i = 0; i + 6 < n; ++i) z[6 + i] = s.eta_dot[i];
    std::vector<ex> h(6);
    for (int r = 0; r < 6; ++r) {
      ex row = 0;
      for (int k = 0; k < n; ++k) row += s.M_body(r, k) * z[k];
      h[r] = ctx.A.let(row);
    }
    const SV3 pN = ctx.A.mul(s.R_NB, SV3{{h[0], h[1], h[2]}});
    const SV3 HN = ctx.A.add(ctx.A.cross(s.r_NO_N, pN), ctx.A.mul(s.R_NB, SV3{{h[3], h[4], h[5]}}));
    p = ctx.A.add(p, pN);
    H = ctx.A.add(H, HN);
  }
  return {p[0], p[1], p[2], H[0], H[1], H[2]};
}

}  // namespace kanegen::codegen
