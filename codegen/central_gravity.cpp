// Central gravity in the generated code: the symbolic counterpart of
// dynamics/central_gravity.hpp (the same MacCullagh potential per rigid part
// and per node, its exact derivatives, the same J2 term), formed in each
// body's own axes so that it shares R_NB, r_NO_N and the displaced node
// positions with the kinematics and the body terms:
//   r_B = R_NB^T r_NO_N + s_B,  z = e_z(N) . r (e_z(N) in B: row 3 of R_NB),
//   f_B = -mu m r/|r|^3 - 3/2 mu/|r|^5 (tr I r + 2 I r - 5 (r.Ir)/|r|^2 r)
//         - k/|r|^7 ((3|r|^2 - 15 z^2) r + 6 |r|^2 z e_z),  k = mu m J2 R^2 / 2,
//   t_B = 3 mu/|r|^5 (r x I r),
// added to g_body as [f; s x f + t; Pt^T f + H^T t].
#include <fmt/format.h>

#include "codegen/kane_context.hpp"

namespace kanegen::codegen {

using namespace GiNaC;

ex KaneContext::central_mu() {
  if (auto p = param(ParameterKind::central, -1, 0)) return *p;
  return C.value(model.central->mu, "central_mu", "m^3/s^2", "gravitational parameter of the central body");
}

ex KaneContext::central_J2() {
  if (auto p = param(ParameterKind::central, -1, 1)) return *p;
  return model.central->J2 == 0.0 ? ex(0) : C.value(model.central->J2, "central_J2", "", "the central body's J2");
}

namespace {

struct ElementField {
  SV3 f_B, t_B;
  ex V;
};

/// The field on one element at r_B (B components) with e_z(N) in B.
ElementField field_on(KaneContext& ctx, const ex& mu, const ex& J2R2, const SymMassElement& e, const SV3& r,
                      const SV3& ez_B, bool potential) {
  Alg& A = ctx.A;
  ElementField out;
  const ex r2 = A.dot(r, r);
  const ex inv_r = A.let(1 / sqrt(r2));
  const ex inv_r2 = A.let(1 / r2), inv_r3 = A.let(inv_r * inv_r2), inv_r5 = A.let(inv_r3 * inv_r2);
  const ex mum = A.let(mu * e.mass);
  out.f_B = A.scale(A.let(-mum * inv_r3), r);
  if (potential) out.V = -mum * inv_r;
  if (e.has_inertia) {
    const SV3 Ir = A.mul(e.I_B, r);
    const ex tr = e.I_B(0, 0) + e.I_B(1, 1) + e.I_B(2, 2);
    const ex rIr = A.dot(r, Ir);
    const ex c = A.let(-ex(3) / 2 * mu * inv_r5);
    const ex rcoef = A.let(c * (tr - 5 * rIr * inv_r2));
    for (int a = 0; a < 3; ++a) out.f_B[a] = A.let(out.f_B[a] + rcoef * r[a] + 2 * c * Ir[a]);
    out.t_B = A.scale(A.let(3 * mu * inv_r5), A.cross(r, Ir));
    if (potential) out.V += -mu / 2 * inv_r3 * (tr - 3 * rIr * inv_r2);
  }
  if (!J2R2.is_zero() && !e.mass.is_zero()) {
    const ex k = A.let(mum * J2R2 / 2);
    const ex z = A.dot(ez_B, r), z2 = A.let(z * z);
    const ex inv_r7 = A.let(inv_r5 * inv_r2);
    const ex kr7 = A.let(-k * inv_r7);
    const ex cr = A.let(kr7 * (3 * r2 - 15 * z2)), cz = A.let(kr7 * 6 * r2 * z);
    for (int a = 0; a < 3; ++a) out.f_B[a] = A.let(out.f_B[a] + cr * r[a] + cz * ez_B[a]);
    if (potential) out.V += k * (3 * z2 - r2) * inv_r5;
  }
  return out;
}

/// r_NO in B and e_z(N) in B, bound once per body.
std::pair<SV3, SV3> body_origin_in_B(KaneContext& ctx, int j) {
  SymBodyWorkspace& s = ctx.body[j];
  const SV3 rO_B = ctx.A.mul_t(s.R_NB, s.r_NO_N, ctx.name("r_NO_B", j));
  SV3 ez_B;
  for (int a = 0; a < 3; ++a) ez_B[a] = s.R_NB(2, a);
  return {rO_B, ez_B};
}

ex J2_R2(KaneContext& ctx) {
  const ex J2 = ctx.central_J2();
  if (J2.is_zero()) return 0;
  const double R = ctx.model.central->radius;
  return ctx.A.let(J2 * ctx.C.value(R * R, "central_radius_sq", "m^2", "the central body's reference radius squared"));
}

}  // namespace

void add_central_gravity_forces(KaneContext& ctx, int j) {
  SymBodyWorkspace& s = ctx.body[j];
  if (s.elements.empty()) return;
  Alg& A = ctx.A;
  ctx.C.group = "model";
  const ex mu = ctx.central_mu(), J2R2 = J2_R2(ctx);
  ctx.C.group = ctx.model.bodies[j].name;
  ctx.P.section(fmt::format("body {}: central gravity on {} mass elements", ctx.model.bodies[j].name, s.elements.size()));
  const auto [rO_B, ez_B] = body_origin_in_B(ctx, j);
  const int m = static_cast<int>(s.g_body.size()) - 6;
  for (const SymMassElement& e : s.elements) {
    const SV3 r = A.add(rO_B, e.s_B);
    const ElementField f = field_on(ctx, mu, J2R2, e, r, ez_B, false);
    const SV3 sxf = A.cross(e.s_B, f.f_B);
    for (int a = 0; a < 3; ++a) {
      s.g_body[a] = s.g_body[a] + f.f_B[a];
      s.g_body[3 + a] = s.g_body[3 + a] + sxf[a] + f.t_B[a];
    }
    for (int i = 0; i < m && i < static_cast<int>(e.Pt.size()); ++i) s.g_body[6 + i] = s.g_body[6 + i] + A.dot(e.Pt[i], f.f_B);
    for (int i = 0; i < m && i < static_cast<int>(e.H.size()); ++i) s.g_body[6 + i] = s.g_body[6 + i] + A.dot(e.H[i], f.t_B);
  }
  for (auto& g : s.g_body) g = A.let(g);
}

ex central_potential(KaneContext& ctx, int j) {
  SymBodyWorkspace& s = ctx.body[j];
  if (s.elements.empty()) return 0;
  ctx.C.group = "model";
  const ex mu = ctx.central_mu(), J2R2 = J2_R2(ctx);
  ctx.C.group = ctx.model.bodies[j].name;
  const auto [rO_B, ez_B] = body_origin_in_B(ctx, j);
  ex V = 0;
  for (const SymMassElement& e : s.elements) V += field_on(ctx, mu, J2R2, e, ctx.A.add(rO_B, e.s_B), ez_B, true).V;
  return ctx.A.let(V);
}

SV3 central_field_at(KaneContext& ctx, const SV3& r_N) {
  ctx.C.group = "model";
  SymMassElement unit;
  unit.mass = 1;
  const SV3 ez{{0, 0, 1}};
  return field_on(ctx, ctx.central_mu(), J2_R2(ctx), unit, r_N, ez, false).f_B;
}

}  // namespace kanegen::codegen
