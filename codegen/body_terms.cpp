// Symbolic per-body inertia, velocity and gravity terms in the body's own
// velocity coordinates z = [v_O_B, w_B, eta_dot], from its mass integrals
// (dynamics/body_inertia.hpp derives them; the same formulas in numbers).
// Unlike the generic engine, the rich nodes' sums of degree 1 and 2 in eta
// (mass, first moment, participation, modal mass: RichNodeSums) are formed
// once per body from coefficients summed at load, and a rich node adds only
// its terms of degree 3 and 4 and its rotary inertia.
#include <fmt/format.h>

#include <array>

#include "codegen/kane_context.hpp"

namespace kanegen::codegen {

static const char* kAxis[3] = {"x", "y", "z"};

static int levi(int a, int b, int c) { return (a - b) * (b - c) * (c - a) / 2; }

namespace {

/// The integrated part's velocity terms (dynamics/body_inertia.hpp).
template <class PffFn>
void add_integrated_velocity_terms(KaneContext& ctx, int j, const SV3& S, const SM3& J, const std::vector<SV3>& Bc,
                                   const std::vector<ex> (&Q)[3][3], const PffFn& Pff) {
  Alg& A = ctx.A;
  SymBodyWorkspace& s = ctx.body[j];
  const int m = static_cast<int>(Bc.size());
  {
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

/// A rich node's terms, one by one (dynamics/body_inertia.hpp, add_node_terms).
/// With `element`, also the node's mass element for the central field (its position also when massless).
/// `modal_mass`: also its m_k Phi~_i . Phi~_l (where the body does not sum them: modal_mass_summed).
void add_node_terms(KaneContext& ctx, int j, int k, bool with_velocity, bool modal_mass,
                    SymMassElement* element) {
  Alg& A = ctx.A;
  const Body& b = ctx.model.bodies[j];
  const FlexibleData& flex = *b.flex;
  const ModalNode& node = flex.nodes[k];
  SymBodyWorkspace& s = ctx.body[j];
  SMat& M = s.M_body;
  const int m = flex.modes();
  const std::string nn = fmt::format("{}_node{}", b.name, node.id);
  ctx.C.group = b.name;
  ctx.P.section(fmt::format("body {}: node {} (rotary inertia, foreshortening)", b.name, node.id));
  const SV3& w = s.w_B;
  if (node.mass != 0.0 || element) {
    const ex mk = node.mass != 0.0 ? ctx.c(node.mass, nn + "_mass", "kg", "node mass") : ex(0);
    // s_k = rho + Phi eta + 1/2 gamma(eta); Phi~ = Phi + G(eta), row a of G = (Gamma^a eta)^T
    std::vector<SV3> Pt(m);
    SV3 sk = ctx.cvec(node.rho_B, nn + "_rho", "m", "node position (undeformed)");
    SV3 gamma_dd;
    for (int i = 0; i < m; ++i) {
      Pt[i] = ctx.cvec(flex.Phi.block(3 * k, i, 3, 1), fmt::format("{}_Phi{}", nn, i + 1), "m",
                       fmt::format("translational shape of mode {} at the node", i + 1));
      for (int a = 0; a < 3; ++a) sk[a] = sk[a] + Pt[i][a] * s.eta[i];
    }
    for (int a = 0; a < 3 && flex.has_second_order(k); ++a) {
      const MatX& G = flex.Gamma[k][a];
      if (G.size() == 0) continue;
      auto Gc = [&](int i, int l) {
        return ctx.c(G(std::min(i, l), std::max(i, l)),
                     fmt::format("{}_Gamma{}_{}_{}", nn, kAxis[a], std::min(i, l) + 1, std::max(i, l) + 1), "1/m",
                     "second-order (foreshortening) coefficient");
      };
      ex quad = 0, dd = 0;
      for (int i = 0; i < m; ++i) {
        ex row = 0, row_dot = 0;
        for (int l = 0; l < m; ++l) {
          row += Gc(i, l) * s.eta[l];
          if (with_velocity) row_dot += Gc(i, l) * s.eta_dot[l];
        }
        const ex gi = A.let(row);
        quad += gi * s.eta[i];
        Pt[i][a] = A.let(Pt[i][a] + gi);
        if (with_velocity) dd += A.let(row_dot) * s.eta_dot[i];
      }
      sk[a] = sk[a] + quad / 2;
      gamma_dd[a] = A.let(dd);
    }
    sk = A.let(sk, ctx.name("s_B", j) + fmt::format("_node{}", node.id));
    if (element) element->mass = mk, element->s_B = sk, element->Pt = Pt;
    if (node.mass != 0.0) {
    // Only the sums of degree 3 and 4 in eta here: the mass, first moment, participation, modal mass and
    // gravity of the node, and the translational part of its remainder force, are in the body's sums
    // (RichNodeSums, compute_body_terms).
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c)
        M(3 + a, 3 + c) = M(3 + a, 3 + c) + mk * ((a == c ? A.dot(sk, sk) : ex(0)) - sk[a] * sk[c]);
    for (int i = 0; i < m; ++i) {
      const SV3 sxP = A.cross(sk, Pt[i]);
      for (int a = 0; a < 3; ++a) M(3 + a, 6 + i) = M(6 + i, 3 + a) = M(3 + a, 6 + i) + mk * sxP[a];
      if (modal_mass)
        for (int l = i; l < m; ++l) M(6 + i, 6 + l) = M(6 + l, 6 + i) = M(6 + i, 6 + l) + mk * A.dot(Pt[i], Pt[l]);
    }
    if (with_velocity) {
      SV3 v_rel;
      for (int a = 0; a < 3; ++a) {
        ex sum = 0;
        for (int i = 0; i < m; ++i) sum += Pt[i][a] * s.eta_dot[i];
        v_rel[a] = A.let(sum);
      }
      SV3 bk = A.add(A.cross(w, A.cross(w, sk)), A.scale(2, A.cross(w, v_rel)));
      bk = A.add(bk, gamma_dd);
      const SV3 sb = A.cross(sk, bk);
      for (int a = 0; a < 3; ++a) s.h_body[3 + a] = s.h_body[3 + a] + mk * sb[a];
      for (int i = 0; i < m; ++i) s.h_body[6 + i] = s.h_body[6 + i] + mk * A.dot(Pt[i], bk);
    }
    }  // node.mass != 0
  }
  if (!node.J_B.isZero(0.0)) {
    // node frame C(Psi eta): J' = C J C^T; w_k = w + H eta_dot, H = (I + g^x) Psi / (1 + g.g), g = Psi eta / 2
    std::vector<SV3> Psi(m), H(m), JH(m);
    SV3 g, g_dot;
    for (int i = 0; i < m; ++i) {
      Psi[i] = ctx.cvec(flex.Psi.block(3 * k, i, 3, 1), fmt::format("{}_Psi{}", nn, i + 1), "rad",
                        fmt::format("rotational shape of mode {} at the node", i + 1));
      for (int a = 0; a < 3; ++a) {
        g[a] = g[a] + Psi[i][a] * s.eta[i] / 2;
        g_dot[a] = g_dot[a] + Psi[i][a] * s.eta_dot[i] / 2;
      }
    }
    g = A.let(g);
    const ex denom = A.let(1 + A.dot(g, g));
    const ex two_over = A.let(2 / denom), inv = A.let(1 / denom);
    const SM3 G = Alg::skew(g);
    SM3 C;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        ex gg = 0;
        for (int t = 0; t < 3; ++t) gg += G(r, t) * G(t, c);
        C(r, c) = A.let((r == c ? 1 : 0) + two_over * (G(r, c) + gg));
      }
    const SM3 Jn = ctx.cmat(node.J_B, nn + "_J", "kg m^2", "node rotary inertia (B axes at eta = 0)", true);
    const SM3 CJ = A.mul(C, Jn);
    SM3 Jp;
    for (int r = 0; r < 3; ++r)
      for (int c = r; c < 3; ++c) {
        ex sum = 0;
        for (int t = 0; t < 3; ++t) sum += CJ(r, t) * C(c, t);
        Jp(r, c) = Jp(c, r) = A.let(sum);
      }
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) M(3 + r, 3 + c) = M(3 + r, 3 + c) + Jp(r, c);
    for (int i = 0; i < m; ++i) {
      const SV3 gx = A.cross(g, Psi[i]);
      for (int a = 0; a < 3; ++a) H[i][a] = A.let((Psi[i][a] + gx[a]) * inv);
      JH[i] = A.mul(Jp, H[i]);
      for (int a = 0; a < 3; ++a) M(3 + a, 6 + i) = M(6 + i, 3 + a) = M(3 + a, 6 + i) + JH[i][a];
    }
    for (int i = 0; i < m; ++i)
      for (int l = i; l < m; ++l) M(6 + i, 6 + l) = M(6 + l, 6 + i) = M(6 + i, 6 + l) + A.dot(H[i], JH[l]);
    if (element) element->I_B = Jp, element->H = H, element->has_inertia = true;
    if (with_velocity) {
      SV3 w_rel;
      for (int a = 0; a < 3; ++a) {
        ex sum = 0;
        for (int i = 0; i < m; ++i) sum += H[i][a] * s.eta_dot[i];
        w_rel[a] = A.let(sum);
      }
      const SV3 w_k = A.add(w, w_rel);
      const ex f = A.let(-2 * A.dot(g, A.let(g_dot)) * inv);
      const SV3 beta = A.add(A.cross(w, w_rel), A.scale(f, w_rel));
      const SV3 torque = A.add(A.mul(Jp, beta), A.cross(w_k, A.mul(Jp, w_k)));
      for (int a = 0; a < 3; ++a) s.h_body[3 + a] = s.h_body[3 + a] + torque[a];
      for (int i = 0; i < m; ++i) s.h_body[6 + i] = s.h_body[6 + i] + A.dot(H[i], torque);
    }
  }
}


/// Body j's mass, first moment S0 and inertia J0 about O (rigid part and
/// plain nodes, B' components) when some of its rigid part's mass, com or
/// inertia are runtime parameters (given in the model's frame B): the rigid
/// part's share formed from the parameters, the nodes' share kept as constants.
/// With `rigid`, also the rigid part's mass element (com and inertia in B').
void runtime_rigid_part(KaneContext& ctx, int j, ex& mass, SV3& S0, SM3& J0, SymMassElement* rigid) {
  const Body& b = ctx.model.bodies[j];
  const BodyMassIntegrals& I = b.integrals;
  const std::string& n = b.name;
  const Mat3 Q = ctx.R_BBp.empty() ? Mat3::Identity() : ctx.R_BBp[j];
  // nominal rigid part in B' (the framed model's) and in B (the parameters' frame)
  const double m0 = b.rigid.mass;
  const Vec3 c0 = b.rigid.com_B;
  const Mat3 Jr0 = b.rigid.I_c_B + m0 * (c0.squaredNorm() * Mat3::Identity() - c0 * c0.transpose());
  const Vec3 c_B = Q * c0;
  const Mat3 Ic_B = Q * b.rigid.I_c_B * Q.transpose();
  const ex m = ctx.param(ParameterKind::mass, j, 0).value_or(ctx.c(m0, n + "_rigid_mass", "kg", "rigid part's mass"));
  SV3 c;  // B components
  for (int a = 0; a < 3; ++a)
    c[a] = ctx.param(ParameterKind::com, j, a)
               .value_or(ctx.c(c_B(a), fmt::format("{}_rigid_com_{}", n, "xyz"[a]), "m", "rigid part's com, model axes"));
  SM3 Ic;  // B axes
  const int rc[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
  for (int k = 0; k < 6; ++k) {
    const int r = rc[k][0], cc = rc[k][1];
    Ic(r, cc) = Ic(cc, r) =
        ctx.param(ParameterKind::inertia, j, k)
            .value_or(ctx.c(Ic_B(r, cc), fmt::format("{}_rigid_I_{}{}", n, "xyz"[r], "xyz"[cc]), "kg m^2",
                            "rigid part's inertia about its com, model axes"));
  }
  Alg& A = ctx.A;
  SM3 Qt;
  for (int r = 0; r < 3; ++r)
    for (int cc = 0; cc < 3; ++cc) Qt(r, cc) = ctx.c(Q(cc, r), fmt::format("{}_R_BpB_{}{}", n, r, cc), "", "model axes in the generator's");
  const SV3 cp = A.mul(Qt, c);                         // com in B'
  const SM3 Icp = A.mul(A.mul(Qt, Ic), Qt.transpose());  // inertia about the com in B'
  if (rigid) rigid->mass = m, rigid->s_B = cp, rigid->I_B = Icp, rigid->has_inertia = true;
  // the nodes' share: what the integrals hold besides the nominal rigid part (0 for a rigid body)
  auto rest = [](double total, double rigid) {
    const double r = total - rigid;
    return std::abs(r) <= 1e-14 * std::max(std::abs(total), std::abs(rigid)) ? 0.0 : r;
  };
  mass = A.P.let(m + ctx.c(rest(I.mass + I.rich.mass, m0), n + "_nodes_mass", "kg", "mass of the nodes"));
  const ex c2 = A.P.let(cp[0] * cp[0] + cp[1] * cp[1] + cp[2] * cp[2]);
  for (int a = 0; a < 3; ++a) {
    S0[a] = A.P.let(m * cp[a] + ctx.c(rest(I.S0(a) + I.rich.S0(a), m0 * c0(a)), fmt::format("{}_nodes_S0_{}", n, "xyz"[a]),
                                      "kg m", "first moment of the nodes (undeformed)"));
    for (int cc = 0; cc < 3; ++cc)
      J0(a, cc) = A.P.let(Icp(a, cc) + m * ((a == cc ? c2 : ex(0)) - cp[a] * cp[cc]) +
                          ctx.c(rest(I.J0(a, cc), Jr0(a, cc)), fmt::format("{}_nodes_J0_{}{}", n, "xyz"[std::min(a, cc)], "xyz"[std::max(a, cc)]),
                                "kg m^2", "inertia of the plain nodes about O"));
  }
}

/// Whether the rich nodes' modal mass block costs fewer operations from its coefficients (RichNodeSums: an
/// add and a multiply per non-zero coefficient of degree 1 and 2) than node by node (per node and pair of
/// modes the products of the components of Phi~_i and Phi~_l that can be non-zero, their sum, the mass's
/// multiply and an add). A beam's modes bend in one plane each, so Phi~ has two components: 8 modes on 7
/// nodes cost more summed, 4 modes on 13 nodes less (docs/flexible_ops.md).
bool rich_modal_mass_cheaper(const FlexibleData& flex, const std::vector<int>& rich, const RichNodeSums& R) {
  if (R.Y2.empty()) return false;  // beyond RichNodeSums::kMaxModesModalMass modes
  const int m = static_cast<int>(R.Y.rows());
  long coefficients = 0;
  for (int i = 0; i < m; ++i)
    for (int l = i; l < m; ++l) {
      const std::size_t il = static_cast<std::size_t>(i * m + l);
      for (int p = 0; p < m; ++p) {
        coefficients += R.Y1[il](p) != 0.0;
        for (int r = p; r < m; ++r) coefficients += R.Y2[il](p, r) != 0.0;
      }
    }
  long by_node = 0;
  for (int k : rich) {
    if (flex.nodes[static_cast<std::size_t>(k)].mass == 0.0) continue;
    // component a of Phi~_i can be non-zero: Phi[a,i] or row i of Gamma^a
    std::vector<std::array<bool, 3>> nz(static_cast<std::size_t>(m));
    for (int i = 0; i < m; ++i)
      for (int a = 0; a < 3; ++a) {
        bool v = flex.Phi(3 * k + a, i) != 0.0;
        if (flex.has_second_order(k) && flex.Gamma[k][a].size())
          for (int l = 0; l < m; ++l) v = v || flex.Gamma[k][a](std::min(i, l), std::max(i, l)) != 0.0;
        nz[static_cast<std::size_t>(i)][a] = v;
      }
    for (int i = 0; i < m; ++i)
      for (int l = i; l < m; ++l) {
        int products = 0;
        for (int a = 0; a < 3; ++a) products += nz[static_cast<std::size_t>(i)][a] && nz[static_cast<std::size_t>(l)][a];
        if (products) by_node += 2 * products + 1;
      }
  }
  return 2 * coefficients < by_node;
}

}  // namespace

void compute_body_terms(KaneContext& ctx, bool with_velocity) {
  Alg& A = ctx.A;
  const Model& model = ctx.model;
  ctx.C.group = "model";
  const SV3 g_N = ctx.gravity(1.0, "gravity", "gravity in N");
  for (std::size_t j = 0; j < model.bodies.size(); ++j) {
    const Body& b = model.bodies[j];
    const BodyMassIntegrals& I = b.integrals;
    SymBodyWorkspace& s = ctx.body[j];
    ctx.C.group = b.name;
    const std::string& n = b.name;
    const int m = I.m;
    ctx.P.section(fmt::format("body {}: mass and velocity terms", n));
    ex mass;
    SV3 S0;
    SM3 J0;
    const bool runtime_rigid = std::any_of(model.parameters.begin(), model.parameters.end(), [&](const RuntimeParameter& p) {
      return p.body == static_cast<int>(j) &&
             (p.kind == ParameterKind::mass || p.kind == ParameterKind::com || p.kind == ParameterKind::inertia);
    });
    // Central gravity acts on each mass element (dynamics.md, Forces): the rigid part's and each node's.
    const bool central = ctx.has_central();
    s.elements.clear();
    SymMassElement rigid;
    if (runtime_rigid) {
      runtime_rigid_part(ctx, static_cast<int>(j), mass, S0, J0, central ? &rigid : nullptr);
      if (central) s.elements.push_back(rigid);
    } else {
      if (central && (b.rigid.mass != 0.0 || !b.rigid.I_c_B.isZero(0.0))) {
        rigid.mass = ctx.c(b.rigid.mass, n + "_rigid_mass", "kg", "rigid part's mass");
        rigid.s_B = ctx.cvec(b.rigid.com_B, n + "_rigid_com", "m", "rigid part's com");
        rigid.has_inertia = !b.rigid.I_c_B.isZero(0.0);
        if (rigid.has_inertia) rigid.I_B = ctx.cmat(b.rigid.I_c_B, n + "_rigid_I", "kg m^2", "rigid part's inertia about its com", true);
        s.elements.push_back(rigid);
      }
      mass = ctx.c(I.mass + I.rich.mass, n + "_mass", "kg", "mass (rigid part and nodes)");
      S0 = ctx.cvec(I.S0 + I.rich.S0, n + "_S0", "kg m", "first mass moment about O (undeformed)");
      J0 = ctx.cmat(I.J0, n + "_J0", "kg m^2", "inertia about O (undeformed)", true);
    }
    // Modal integrals.
    std::vector<SV3> Bc(m);
    for (int i = 0; i < m; ++i)
      Bc[i] = ctx.cvec(I.rich.nodes > 0 ? Vec3(I.B.col(i) + I.rich.B.col(i)) : Vec3(I.B.col(i)),
                       fmt::format("{}_B{}", n, i + 1), "kg m", "modal participation");
    // The rich nodes' sums of degree 1 and 2 in eta (RichNodeSums, model/modal_integrals.hpp): added here
    // once, not node by node (add_node_terms adds their terms of degree 3 and 4 and their rotary inertia).
    const RichNodeSums& R = I.rich;
    auto Gs = [&](int a, int i, int l) {
      return ctx.c(R.G[a](std::min(i, l), std::max(i, l)),
                   fmt::format("{}_rich_Gamma{}_{}_{}", n, kAxis[a], std::min(i, l) + 1, std::max(i, l) + 1), "kg/m",
                   "Sum m Gamma over the rich nodes");
    };
    // x^T G[a] x over the modal coordinates x (eta in the first moment, eta_dot in the remainder force)
    auto gamma_form = [&](int a, const std::vector<ex>& x) {
      ex sum = 0;
      for (int i = 0; i < m; ++i)
        for (int l = 0; l < m; ++l) sum += Gs(a, i, l) * x[i] * x[l];
      return sum;
    };
    // Bt[i] = Sum m Phi~_i over every node: B_i + [G[a] eta]_i (plain nodes: B_i)
    std::vector<SV3> Bt = Bc;
    for (int i = 0; i < m && R.nodes > 0; ++i)
      for (int a = 0; a < 3; ++a) {
        ex sum = Bc[i][a];
        for (int l = 0; l < m; ++l) sum += Gs(a, i, l) * s.eta[l];
        Bt[i][a] = A.let(sum);
      }
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
      if (R.nodes > 0) sum += gamma_form(a, s.eta) / 2;
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
        s.M_body(a, 6 + i) = s.M_body(6 + i, a) = Bt[i][a];
        ex Cai = 0;  // C[a,i] = eps_abc Q[b][c]_i
        for (int bb = 0; bb < 3; ++bb)
          for (int cc = 0; cc < 3; ++cc)
            if (int e = levi(a, bb, cc)) Cai += e * Q[bb][cc][i];
        s.M_body(3 + a, 6 + i) = s.M_body(6 + i, 3 + a) = A.let(Cai);
      }
      for (int l = 0; l < m; ++l) s.M_body(6 + i, 6 + l) = Yc(i, l);
    }
    // the rich nodes' Sum m Phi~_i . Phi~_l = Y + Y1 . eta + eta^T Y2 eta, where its coefficients cost
    // fewer operations than the nodes' products (m^2 (m + 1)^2 / 4 of degree 2 against ~7 m (m + 1) / 2
    // per node: 8 modes on 7 nodes cost more summed)
    const bool modal_mass_summed = R.nodes > 0 && rich_modal_mass_cheaper(*b.flex, b.rich_nodes, R);
    for (int i = 0; i < m && modal_mass_summed; ++i)
      for (int l = i; l < m; ++l) {
        const std::size_t il = static_cast<std::size_t>(i * m + l);
        ex sum = ctx.c(R.Y(i, l), fmt::format("{}_rich_Y_{}_{}", n, i + 1, l + 1), "kg m^2", "rich nodes' modal mass");
        for (int p = 0; p < m; ++p) {
          sum += ctx.c(R.Y1[il](p), fmt::format("{}_rich_Y1_{}_{}_{}", n, i + 1, l + 1, p + 1), "kg m",
                       "rich nodes' Phi~.Phi~, degree 1") * s.eta[p];
          for (int r = p; r < m; ++r)
            sum += ctx.c((r == p ? 1.0 : 2.0) * R.Y2[il](p, r), fmt::format("{}_rich_Y2_{}_{}_{}_{}", n, i + 1, l + 1, p + 1, r + 1),
                         "kg", "rich nodes' Phi~.Phi~, degree 2") * s.eta[p] * s.eta[r];
        }
        s.M_body(6 + i, 6 + l) = s.M_body(6 + l, 6 + i) = A.let(s.M_body(6 + i, 6 + l) + sum);
      }
    // Gravity: g_B = R_NB^T g_N; [m g_B; S x g_B; B^T g_B]
    s.g_body.assign(6 + m, ex(0));
    SV3 g_B;
    const bool gravity_terms = ctx.has_gravity() && !(with_velocity && ctx.gravity_in_base_acceleration);
    if (gravity_terms) {
      g_B = A.mul_t(s.R_NB, g_N, ctx.name("g_B", static_cast<int>(j)));
      const SV3 mg = A.scale(mass, g_B), Sg = A.cross(S, g_B);
      for (int a = 0; a < 3; ++a) s.g_body[a] = mg[a], s.g_body[3 + a] = Sg[a];
      for (int i = 0; i < m; ++i) s.g_body[6 + i] = A.dot(Bt[i], g_B);
    }
    s.h_body.assign(6 + m, ex(0));
    if (with_velocity) {
      add_integrated_velocity_terms(ctx, static_cast<int>(j), S, J, Bt, Q, Pff);
      // the rich nodes' Sum m eta_dot^T Gamma^a eta_dot (their remainder acceleration's second-order part)
      for (int a = 0; a < 3 && R.nodes > 0; ++a) s.h_body[a] = A.let(s.h_body[a] + gamma_form(a, s.eta_dot));
    }
    if (!central) {
      for (int k : b.rich_nodes) add_node_terms(ctx, static_cast<int>(j), k, with_velocity, !modal_mass_summed, nullptr);
      continue;
    }
    // every node is an element: rich nodes as their terms form them, plain ones at rho + Phi eta
    const int nk = b.flex ? static_cast<int>(b.flex->nodes.size()) : 0;
    for (int k = 0; k < nk; ++k) {
      const FlexibleData& flex = *b.flex;
      const ModalNode& node = flex.nodes[k];
      if (flex.node_is_rich(k)) {
        SymMassElement e;
        add_node_terms(ctx, static_cast<int>(j), k, with_velocity, !modal_mass_summed, &e);
        s.elements.push_back(e);
        continue;
      }
      if (node.mass == 0.0) continue;
      const std::string nn = fmt::format("{}_node{}", n, node.id);
      SymMassElement e;
      e.mass = ctx.c(node.mass, nn + "_mass", "kg", "node mass");
      SV3 sk = ctx.cvec(node.rho_B, nn + "_rho", "m", "node position (undeformed)");
      e.Pt.resize(m);
      for (int i = 0; i < m; ++i) {
        e.Pt[i] = ctx.cvec(flex.Phi.block(3 * k, i, 3, 1), fmt::format("{}_Phi{}", nn, i + 1), "m",
                           fmt::format("translational shape of mode {} at the node", i + 1));
        for (int a = 0; a < 3; ++a) sk[a] = sk[a] + e.Pt[i][a] * s.eta[i];
      }
      e.s_B = A.let(sk, ctx.name("s_B", static_cast<int>(j)) + fmt::format("_node{}", node.id));
      s.elements.push_back(e);
    }
    add_central_gravity_forces(ctx, static_cast<int>(j));
  }
}


}  // namespace kanegen::codegen
