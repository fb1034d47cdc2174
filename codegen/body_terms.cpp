// Symbolic per-body inertia, velocity and gravity terms in the body's own
// velocity coordinates z = [v_O_B, w_B, eta_dot], from its mass integrals
// (dynamics/body_inertia.hpp derives them; the same formulas in numbers).
#include <fmt/format.h>

#include "codegen/kane_context.hpp"

namespace kanegen::codegen {

static const char* kAxis[3] = {"x", "y", "z"};

static int levi(int a, int b, int c) { return (a - b) * (b - c) * (c - a) / 2; }

void compute_body_terms(KaneContext& ctx, bool with_velocity) {
  Alg& A = ctx.A;
  const Model& model = ctx.model;
  const Vec3& gN = model.g_N;
  ctx.C.group = "model";
  const SV3 g_N = ctx.cvec(gN, "gravity", "m/s^2", "gravity in N");
  for (std::size_t j = 0; j < model.bodies.size(); ++j) {
    const Body& b = model.bodies[j];
    const BodyMassIntegrals& I = b.integrals;
    SymBodyWorkspace& s = ctx.body[j];
    ctx.C.group = b.name;
    const std::string& n = b.name;
    const int m = I.m;
    ctx.P.section(fmt::format("body {}: mass and velocity terms", n));
    const ex mass = ctx.c(I.mass, n + "_mass", "kg", "mass (rigid part and nodes)");
    const SV3 S0 = ctx.cvec(I.S0, n + "_S0", "kg m", "first mass moment about O (undeformed)");
    const SM3 J0 = ctx.cmat(I.J0, n + "_J0", "kg m^2", "inertia about O (undeformed)", true);
    // Modal integrals.
    std::vector<SV3> Bc(m);
    for (int i = 0; i < m; ++i) Bc[i] = ctx.cvec(I.B.col(i), fmt::format("{}_B{}", n, i + 1), "kg m", "modal participation");
    auto Yc = [&](int i, int l) {
      return ctx.c(I.Y(std::min(i, l), std::max(i, l)), fmt::format("{}_Y_{}_{}", n, std::min(i, l) + 1, std::max(i, l) + 1),
               "kg m^2", "modal mass");
    };
    auto Prf = [&](int a, int cc, int i) {
      return ctx.c(I.Prf[a][cc](i), fmt::format("{}_Prf_{}{}_{}", n, kAxis[a], kAxis[cc], i + 1), "kg m^2",
               "Sum m rho_a Phi_c");
    };
    auto Pff = [&](int a, int cc, int l, int i) {
      return ctx.c(I.Pff[a][cc](l, i), fmt::format("{}_Pff_{}{}_{}_{}", n, kAxis[a], kAxis[cc], l + 1, i + 1), "kg m^2",
               "Sum m Phi_a Phi_c");
    };
    SV3 S = S0;
    for (int a = 0; a < 3; ++a) {
      ex sum = S0[a];
      for (int i = 0; i < m; ++i) sum += Bc[i][a] * s.eta[i];
      S[a] = A.let(sum, Alg::component(ctx.name("S_B", static_cast<int>(j)), a));
    }
    SM3 J = J0;
    // Q[a][c][i] = Sum m s_a Phi_c,i
    std::vector<ex> Q[3][3];
    if (m > 0) {
      for (int a = 0; a < 3; ++a)
        for (int cc = 0; cc < 3; ++cc) {
          Q[a][cc].resize(m);
          for (int i = 0; i < m; ++i) {
            ex sum = Prf(a, cc, i);
            for (int l = 0; l < m; ++l) sum += Pff(a, cc, l, i) * s.eta[l];
            Q[a][cc][i] = A.let(sum);
          }
        }
      SM3 D;
      for (int a = 0; a < 3; ++a)
        for (int cc = 0; cc < 3; ++cc) {
          ex sum = 0;
          for (int i = 0; i < m; ++i) sum += Prf(cc, a, i) * s.eta[i] + Q[a][cc][i] * s.eta[i];
          D(a, cc) = A.let(sum);
        }
      const ex tr = A.let(D(0, 0) + D(1, 1) + D(2, 2));
      for (int a = 0; a < 3; ++a)
        for (int cc = 0; cc < 3; ++cc) J(a, cc) = A.let(J0(a, cc) + (a == cc ? tr : ex(0)) - D(a, cc));
    }
    // M_body
    s.M_body = SMat(6 + m, 6 + m);
    for (int a = 0; a < 3; ++a) s.M_body(a, a) = mass;
    const SM3 Sx = Alg::skew(S);
    for (int a = 0; a < 3; ++a)
      for (int cc = 0; cc < 3; ++cc) {
        s.M_body(a, 3 + cc) = -Sx(a, cc);
        s.M_body(3 + a, cc) = Sx(a, cc);
        s.M_body(3 + a, 3 + cc) = J(a, cc);
      }
    for (int i = 0; i < m; ++i) {
      for (int a = 0; a < 3; ++a) {
        s.M_body(a, 6 + i) = s.M_body(6 + i, a) = Bc[i][a];
        ex Cai = 0;  // C[a,i] = eps_abc Q[b][c]_i
        for (int bb = 0; bb < 3; ++bb)
          for (int cc = 0; cc < 3; ++cc)
            if (int e = levi(a, bb, cc)) Cai += e * Q[bb][cc][i];
        s.M_body(3 + a, 6 + i) = s.M_body(6 + i, 3 + a) = A.let(Cai);
      }
      for (int l = 0; l < m; ++l) s.M_body(6 + i, 6 + l) = Yc(i, l);
    }
    // Gravity: g_B = R_NB^T g_N; [m g_B; S x g_B; B^T g_B]
    s.g_body.assign(6 + m, ex(0));
    if (!gN.isZero()) {
      const SV3 g_B = A.mul_t(s.R_NB, g_N, ctx.name("g_B", static_cast<int>(j)));
      const SV3 mg = A.scale(mass, g_B), Sg = A.cross(S, g_B);
      for (int a = 0; a < 3; ++a) s.g_body[a] = mg[a], s.g_body[3 + a] = Sg[a];
      for (int i = 0; i < m; ++i) s.g_body[6 + i] = A.dot(Bc[i], g_B);
    }
    if (!with_velocity) continue;
    // Velocity terms.
    s.h_body.assign(6 + m, ex(0));
    const SV3& w = s.w_B;
    SV3 Bed;
    for (int a = 0; a < 3; ++a) {
      ex sum = 0;
      for (int i = 0; i < m; ++i) sum += Bc[i][a] * s.eta_dot[i];
      Bed[a] = A.let(sum);
    }
    const SV3 hv = A.add(A.cross(w, A.cross(w, S)), A.scale(2, A.cross(w, Bed)));
    SV3 hw = A.cross(w, A.mul(J, w));
    if (m > 0) {
      SM3 G;  // G[a][c] = Q[c][a] . eta_dot
      for (int a = 0; a < 3; ++a)
        for (int cc = 0; cc < 3; ++cc) {
          ex sum = 0;
          for (int i = 0; i < m; ++i) sum += Q[cc][a][i] * s.eta_dot[i];
          G(a, cc) = A.let(sum);
        }
      const ex trG = A.let(G(0, 0) + G(1, 1) + G(2, 2));
      const SV3 Gw = A.mul(G, w);
      for (int a = 0; a < 3; ++a) hw[a] = A.let(hw[a] + 2 * (trG * w[a] - Gw[a]));
      const ex w2 = A.dot(w, w);
      for (int i = 0; i < m; ++i) {
        ex sum = 0;
        for (int a = 0; a < 3; ++a) {
          sum -= w2 * Q[a][a][i];
          for (int cc = 0; cc < 3; ++cc) {
            sum += w[a] * w[cc] * Q[cc][a][i];
            for (int bb = 0; bb < 3; ++bb)
              if (int e = levi(a, bb, cc)) {
                ex pe = 0;
                for (int l = 0; l < m; ++l) pe += Pff(a, cc, i, l) * s.eta_dot[l];
                sum += 2 * e * w[bb] * pe;
              }
          }
        }
        s.h_body[6 + i] = A.let(sum);
      }
    }
    for (int a = 0; a < 3; ++a) s.h_body[a] = hv[a], s.h_body[3 + a] = hw[a];
  }
}


}  // namespace kanegen::codegen
