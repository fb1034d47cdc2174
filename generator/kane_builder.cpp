#include "kane_builder.hpp"

#include <fmt/format.h>

#include "rotation.hpp"

namespace kanegen::gen {

using namespace GiNaC;

static const char* kAxis[3] = {"x", "y", "z"};

StateSymbols::StateSymbols(const Model& m) {
  for (int i = 0; i < m.nq; ++i) q.push_back(symbol(fmt::format("q[{}]", i)));
  for (int i = 0; i < m.nu; ++i) {
    u.push_back(symbol(fmt::format("u[{}]", i)));
    tau.push_back(symbol(fmt::format("tau[{}]", i)));
    udot.push_back(symbol(fmt::format("udot_in[{}]", i)));
  }
}

KaneBuilder::KaneBuilder(const Model& model, Program& program, Constants& constants, const StateSymbols& x)
    : model_(model), P_(program), C_(constants), x_(x), A_(program), body_(model.bodies.size()) {}

ex KaneBuilder::c(double v, const std::string& name, const std::string& unit, const std::string& what) {
  return C_.value(v, name, unit, what);
}

SV3 KaneBuilder::cvec(const Vec3& v, const std::string& name, const std::string& unit, const std::string& what) {
  SV3 r;
  for (int i = 0; i < 3; ++i) r[i] = c(v(i), name + "_" + kAxis[i], unit, what + " " + kAxis[i]);
  return r;
}

SM3 KaneBuilder::cmat(const Mat3& m, const std::string& name, const std::string& unit, const std::string& what,
                      bool symmetric) {
  SM3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const int a = symmetric ? std::min(i, j) : i, b = symmetric ? std::max(i, j) : j;
      r(i, j) = c(m(a, b), fmt::format("{}_{}{}", name, kAxis[a], kAxis[b]), unit, what);
    }
  return r;
}

std::vector<int> KaneBuilder::own_columns(int j) const {
  const Body& b = model_.bodies[j];
  std::vector<int> cols;
  for (int k = 0; k < joint_nu(b.joint.type) + b.n_modes(); ++k) cols.push_back(b.u_joint + k);
  return cols;
}

// ---------------------------------------------------------------------------
void KaneBuilder::kinematics(bool with_velocity) {
  for (std::size_t i = 0; i < model_.bodies.size(); ++i) {
    const Body& b = model_.bodies[i];
    SymBody& s = body_[i];
    C_.group = b.name;
    const std::string& n = b.name;
    const int m = b.n_modes();
    s.eta.clear(), s.eta_dot.clear();
    for (int k = 0; k < m; ++k) {
      s.eta.push_back(x_.q[b.q_eta + k]);
      s.eta_dot.push_back(x_.u[b.u_eta + k]);
    }
    const bool has_parent = b.parent >= 0;
    const SymBody* p = has_parent ? &body_[b.parent] : nullptr;
    const SV3 zero;
    const SV3 w_P = has_parent ? p->w : zero, v_P = has_parent ? p->v : zero;
    const SV3 aR_P = has_parent ? p->aR : zero, alR_P = has_parent ? p->alR : zero;

    // Joint frame.
    SM3 R_PJ = cmat(b.joint.R_PJ, n + "_R_PJ", "", "joint frame orientation in the parent");
    SV3 p_PJ;
    SV3 w_J, w_J_dot_R, v_node;
    std::vector<SV3> H_cols, Phi_cols;  // per parent mode
    const int m_P = has_parent ? model_.bodies[b.parent].n_modes() : 0;
    if (b.joint.node >= 0) {
      const FlexibleData& pf = *model_.bodies[b.parent].flex;
      const int k = b.joint.node;
      const std::string nn = fmt::format("{}_node{}", n, pf.nodes[k].id);
      for (int mode = 0; mode < m_P; ++mode) {
        Phi_cols.push_back(cvec(pf.Phi.block(3 * k, mode, 3, 1), fmt::format("{}_Phi{}", nn, mode + 1), "m",
                                fmt::format("translational shape of mode {} at the attachment node", mode + 1)));
      }
      std::vector<SV3> Psi_cols;
      for (int mode = 0; mode < m_P; ++mode)
        Psi_cols.push_back(cvec(pf.Psi.block(3 * k, mode, 3, 1), fmt::format("{}_Psi{}", nn, mode + 1), "rad",
                                fmt::format("rotational shape of mode {} at the attachment node", mode + 1)));
      // g = Psi eta / 2, C(g) = I + 2/(1+g.g) (g^x + g^x g^x)
      SV3 g;
      for (int a = 0; a < 3; ++a) {
        ex sum = 0;
        for (int mode = 0; mode < m_P; ++mode) sum += Psi_cols[mode][a] * p->eta[mode];
        g[a] = A_.let(sum / 2);
      }
      const ex denom = A_.let(1 + g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
      const ex two_over = A_.let(2 / denom);
      const SM3 G = Alg::skew(g);
      SM3 Cg;
      for (int r = 0; r < 3; ++r)
        for (int cc = 0; cc < 3; ++cc) {
          ex gg = 0;
          for (int t = 0; t < 3; ++t) gg += G(r, t) * G(t, cc);
          Cg(r, cc) = A_.let((r == cc ? 1 : 0) + two_over * (G(r, cc) + gg));
        }
      R_PJ = A_.mul(Cg, R_PJ);
      const SV3 rho = cvec(pf.nodes[k].rho_B, nn + "_rho", "m", "attachment node position in the parent");
      for (int a = 0; a < 3; ++a) {
        ex sum = rho[a];
        for (int mode = 0; mode < m_P; ++mode) sum += Phi_cols[mode][a] * p->eta[mode];
        p_PJ[a] = A_.let(sum);
      }
      // H = (I + g^x) Psi / (1 + g.g): w_J = H eta_dot_P
      const ex inv = A_.let(1 / denom);
      for (int mode = 0; mode < m_P; ++mode) {
        SV3 h;
        const SV3 gx = A_.cross(g, Psi_cols[mode]);
        for (int a = 0; a < 3; ++a) h[a] = A_.let((Psi_cols[mode][a] + gx[a]) * inv);
        H_cols.push_back(h);
      }
      if (with_velocity) {
        for (int a = 0; a < 3; ++a) {
          ex wj = 0, vn = 0;
          for (int mode = 0; mode < m_P; ++mode) {
            wj += H_cols[mode][a] * p->eta_dot[mode];
            vn += Phi_cols[mode][a] * p->eta_dot[mode];
          }
          w_J[a] = A_.let(wj);
          v_node[a] = A_.let(vn);
        }
        SV3 g_dot;
        for (int a = 0; a < 3; ++a) {
          ex sum = 0;
          for (int mode = 0; mode < m_P; ++mode) sum += Psi_cols[mode][a] * p->eta_dot[mode];
          g_dot[a] = A_.let(sum / 2);
        }
        const ex f = A_.let(-2 * A_.dot(g, g_dot) * inv);
        w_J_dot_R = A_.scale(f, w_J);
      }
    } else {
      p_PJ = cvec(b.joint.p_PJ, n + "_p_PJ", "m", "joint frame origin in the parent");
    }

    // Joint motion.
    SM3 R_JB = SM3::identity();
    SV3 e, e_dot, w_rel;
    const SV3 axis = cvec(b.joint.axis_J, n + "_axis", "", "joint axis");
    switch (b.joint.type) {
      case JointType::revolute: {
        const ex cq = A_.let(cos(x_.q[b.q_joint])), sq = A_.let(sin(x_.q[b.q_joint]));
        // Rot(a, th) = a a^T + cos th (I - a a^T) + sin th a^x
        const Eigen::Matrix3d aa = b.joint.axis_J * b.joint.axis_J.transpose();
        const SM3 Ax = Alg::skew(axis);
        for (int r = 0; r < 3; ++r)
          for (int cc = 0; cc < 3; ++cc) {
            const int lo = std::min(r, cc), hi = std::max(r, cc);
            const ex aa_rc = c(aa(r, cc), fmt::format("{}_axis_aa_{}{}", n, kAxis[lo], kAxis[hi]), "", "axis outer product");
            const ex one_minus = c((r == cc ? 1.0 : 0.0) - aa(r, cc),
                                   fmt::format("{}_axis_Iaa_{}{}", n, kAxis[lo], kAxis[hi]), "", "I - axis outer product");
            R_JB(r, cc) = A_.let(aa_rc + cq * one_minus + sq * Ax(r, cc));
          }
        if (with_velocity) w_rel = A_.scale(x_.u[b.u_joint], A_.mul(R_PJ, axis));
        break;
      }
      case JointType::prismatic: {
        const SV3 a_P = A_.mul(R_PJ, axis);
        e = A_.scale(x_.q[b.q_joint], a_P);
        if (with_velocity) e_dot = A_.scale(x_.u[b.u_joint], a_P);
        break;
      }
      case JointType::fixed: break;
      case JointType::free: {
        const int q0 = b.q_joint;
        const ex inv_norm = A_.let(1 / sqrt(x_.q[q0 + 3] * x_.q[q0 + 3] + x_.q[q0 + 4] * x_.q[q0 + 4] +
                                            x_.q[q0 + 5] * x_.q[q0 + 5] + x_.q[q0 + 6] * x_.q[q0 + 6]));
        const ex w = A_.let(x_.q[q0 + 3] * inv_norm), xq = A_.let(x_.q[q0 + 4] * inv_norm),
                 y = A_.let(x_.q[q0 + 5] * inv_norm), z = A_.let(x_.q[q0 + 6] * inv_norm);
        const ex xx = A_.let(xq * xq), yy = A_.let(y * y), zz = A_.let(z * z);
        const ex xy = A_.let(xq * y), xz = A_.let(xq * z), yz = A_.let(y * z);
        const ex wx = A_.let(w * xq), wy = A_.let(w * y), wz = A_.let(w * z);
        R_JB(0, 0) = A_.let(1 - 2 * (yy + zz)), R_JB(0, 1) = A_.let(2 * (xy - wz)), R_JB(0, 2) = A_.let(2 * (xz + wy));
        R_JB(1, 0) = A_.let(2 * (xy + wz)), R_JB(1, 1) = A_.let(1 - 2 * (xx + zz)), R_JB(1, 2) = A_.let(2 * (yz - wx));
        R_JB(2, 0) = A_.let(2 * (xz - wy)), R_JB(2, 1) = A_.let(2 * (yz + wx)), R_JB(2, 2) = A_.let(1 - 2 * (xx + yy));
        const SV3 xyz{{x_.q[q0], x_.q[q0 + 1], x_.q[q0 + 2]}};
        e = A_.mul(R_PJ, xyz);
        break;
      }
    }
    s.R_PB = A_.mul(R_PJ, R_JB);
    s.d = A_.add(p_PJ, e);
    const SM3 R_BP = s.R_PB.transpose();
    if (b.joint.type == JointType::free && with_velocity) {
      const int u0 = b.u_joint;
      const SV3 v{{x_.u[u0], x_.u[u0 + 1], x_.u[u0 + 2]}}, w{{x_.u[u0 + 3], x_.u[u0 + 4], x_.u[u0 + 5]}};
      e_dot = A_.mul(s.R_PB, v);
      w_rel = A_.mul(s.R_PB, w);
    }
    if (has_parent) {
      s.R_NB = A_.mul(p->R_NB, s.R_PB);
      s.r_NO = A_.add(p->r_NO, A_.mul(p->R_NB, s.d));
    } else {
      s.R_NB = s.R_PB;
      s.r_NO = s.d;
    }
    // Node coupling: partials of [v; w] w.r.t. the parent's modal speeds.
    s.N.clear();
    for (int mode = 0; mode < static_cast<int>(H_cols.size()); ++mode) {
      const SV3 lin = A_.mul(R_BP, A_.sub(Phi_cols[mode], A_.cross(e, H_cols[mode])));
      const SV3 ang = A_.mul(R_BP, H_cols[mode]);
      s.N.push_back({lin[0], lin[1], lin[2], ang[0], ang[1], ang[2]});
    }
    if (!with_velocity) continue;
    const SV3 w_BP = A_.add(w_J, w_rel);
    const SV3 v_rel = A_.add(A_.add(v_node, A_.cross(w_J, e)), e_dot);
    s.w = A_.mul(R_BP, A_.add(w_P, w_BP));
    s.v = A_.mul(R_BP, A_.add(A_.add(v_P, A_.cross(w_P, s.d)), v_rel));
    SV3 al = A_.add(A_.add(alR_P, A_.cross(w_P, w_BP)), A_.add(w_J_dot_R, A_.cross(w_J, w_rel)));
    s.alR = A_.mul(R_BP, al);
    SV3 a = A_.add(aR_P, A_.cross(alR_P, s.d));
    a = A_.add(a, A_.cross(w_P, A_.cross(w_P, s.d)));
    a = A_.add(a, A_.scale(2, A_.cross(w_P, v_rel)));
    a = A_.add(a, A_.cross(w_J_dot_R, e));
    a = A_.add(a, A_.cross(w_J, A_.cross(w_J, e)));
    a = A_.add(a, A_.cross(w_J, e_dot));
    a = A_.add(a, A_.cross(w_BP, e_dot));
    s.aR = A_.mul(R_BP, a);
  }
}

// ---------------------------------------------------------------------------
static int levi(int a, int b, int c) { return (a - b) * (b - c) * (c - a) / 2; }

void KaneBuilder::body_terms(bool with_velocity) {
  const Vec3& gN = model_.g_N;
  C_.group = "model";
  const SV3 g_N = cvec(gN, "gravity", "m/s^2", "gravity in N");
  for (std::size_t j = 0; j < model_.bodies.size(); ++j) {
    const Body& b = model_.bodies[j];
    const BodyMassIntegrals& I = b.integrals;
    SymBody& s = body_[j];
    C_.group = b.name;
    const std::string& n = b.name;
    const int m = I.m;
    const ex mass = c(I.mass, n + "_mass", "kg", "mass (rigid part and nodes)");
    const SV3 S0 = cvec(I.S0, n + "_S0", "kg m", "first mass moment about O (undeformed)");
    const SM3 J0 = cmat(I.J0, n + "_J0", "kg m^2", "inertia about O (undeformed)", true);
    // Modal integrals.
    std::vector<SV3> Bc(m);
    for (int i = 0; i < m; ++i) Bc[i] = cvec(I.B.col(i), fmt::format("{}_B{}", n, i + 1), "kg m", "modal participation");
    auto Yc = [&](int i, int k) {
      return c(I.Y(std::min(i, k), std::max(i, k)), fmt::format("{}_Y_{}_{}", n, std::min(i, k) + 1, std::max(i, k) + 1),
               "kg m^2", "modal mass");
    };
    auto Prf = [&](int a, int cc, int i) {
      return c(I.Prf[a][cc](i), fmt::format("{}_Prf_{}{}_{}", n, kAxis[a], kAxis[cc], i + 1), "kg m^2",
               "Sum m rho_a Phi_c");
    };
    auto Pff = [&](int a, int cc, int l, int i) {
      return c(I.Pff[a][cc](l, i), fmt::format("{}_Pff_{}{}_{}_{}", n, kAxis[a], kAxis[cc], l + 1, i + 1), "kg m^2",
               "Sum m Phi_a Phi_c");
    };
    SV3 S = S0;
    for (int a = 0; a < 3; ++a) {
      ex sum = S0[a];
      for (int i = 0; i < m; ++i) sum += Bc[i][a] * s.eta[i];
      S[a] = A_.let(sum);
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
            Q[a][cc][i] = A_.let(sum);
          }
        }
      SM3 D;
      for (int a = 0; a < 3; ++a)
        for (int cc = 0; cc < 3; ++cc) {
          ex sum = 0;
          for (int i = 0; i < m; ++i) sum += Prf(cc, a, i) * s.eta[i] + Q[a][cc][i] * s.eta[i];
          D(a, cc) = A_.let(sum);
        }
      const ex tr = A_.let(D(0, 0) + D(1, 1) + D(2, 2));
      for (int a = 0; a < 3; ++a)
        for (int cc = 0; cc < 3; ++cc) J(a, cc) = A_.let(J0(a, cc) + (a == cc ? tr : ex(0)) - D(a, cc));
    }
    // M_body
    s.Mb = SMat(6 + m, 6 + m);
    for (int a = 0; a < 3; ++a) s.Mb(a, a) = mass;
    const SM3 Sx = Alg::skew(S);
    for (int a = 0; a < 3; ++a)
      for (int cc = 0; cc < 3; ++cc) {
        s.Mb(a, 3 + cc) = -Sx(a, cc);
        s.Mb(3 + a, cc) = Sx(a, cc);
        s.Mb(3 + a, 3 + cc) = J(a, cc);
      }
    for (int i = 0; i < m; ++i) {
      for (int a = 0; a < 3; ++a) {
        s.Mb(a, 6 + i) = s.Mb(6 + i, a) = Bc[i][a];
        ex Cai = 0;  // C[a,i] = eps_abc Q[b][c]_i
        for (int bb = 0; bb < 3; ++bb)
          for (int cc = 0; cc < 3; ++cc)
            if (int e = levi(a, bb, cc)) Cai += e * Q[bb][cc][i];
        s.Mb(3 + a, 6 + i) = s.Mb(6 + i, 3 + a) = A_.let(Cai);
      }
      for (int k = 0; k < m; ++k) s.Mb(6 + i, 6 + k) = Yc(i, k);
    }
    // Gravity: g_B = R_NB^T g_N; [m g_B; S x g_B; B^T g_B]
    s.g.assign(6 + m, ex(0));
    if (!gN.isZero()) {
      const SV3 g_B = A_.mul_t(s.R_NB, g_N);
      const SV3 mg = A_.scale(mass, g_B), Sg = A_.cross(S, g_B);
      for (int a = 0; a < 3; ++a) s.g[a] = mg[a], s.g[3 + a] = Sg[a];
      for (int i = 0; i < m; ++i) s.g[6 + i] = A_.dot(Bc[i], g_B);
    }
    if (!with_velocity) continue;
    // Velocity terms.
    s.h.assign(6 + m, ex(0));
    const SV3& w = s.w;
    SV3 Bed;
    for (int a = 0; a < 3; ++a) {
      ex sum = 0;
      for (int i = 0; i < m; ++i) sum += Bc[i][a] * s.eta_dot[i];
      Bed[a] = A_.let(sum);
    }
    const SV3 hv = A_.add(A_.cross(w, A_.cross(w, S)), A_.scale(2, A_.cross(w, Bed)));
    SV3 hw = A_.cross(w, A_.mul(J, w));
    if (m > 0) {
      SM3 G;  // G[a][c] = Q[c][a] . eta_dot
      for (int a = 0; a < 3; ++a)
        for (int cc = 0; cc < 3; ++cc) {
          ex sum = 0;
          for (int i = 0; i < m; ++i) sum += Q[cc][a][i] * s.eta_dot[i];
          G(a, cc) = A_.let(sum);
        }
      const ex trG = A_.let(G(0, 0) + G(1, 1) + G(2, 2));
      const SV3 Gw = A_.mul(G, w);
      for (int a = 0; a < 3; ++a) hw[a] = A_.let(hw[a] + 2 * (trG * w[a] - Gw[a]));
      const ex w2 = A_.dot(w, w);
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
        s.h[6 + i] = A_.let(sum);
      }
    }
    for (int a = 0; a < 3; ++a) s.h[a] = hv[a], s.h[3 + a] = hw[a];
  }
}

// ---------------------------------------------------------------------------
std::vector<std::vector<ex>> KaneBuilder::motion_subspace(int j) {
  const Body& b = model_.bodies[j];
  const int m = b.n_modes();
  std::vector<std::vector<ex>> S;
  C_.group = b.name;
  const SV3 axis = cvec(b.joint.axis_J, b.name + "_axis", "", "joint axis");
  switch (b.joint.type) {
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
      for (int k = 0; k < 6; ++k) {
        std::vector<ex> col(6 + m, ex(0));
        col[k] = 1;
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

std::vector<ex> KaneBuilder::transform_motion_from_parent(int j, const std::vector<ex>* dp) {
  const SymBody& s = body_[j];
  std::vector<ex> dl(6 + model_.bodies[j].n_modes(), ex(0));
  if (!dp) return dl;
  const SM3 R_BP = s.R_PB.transpose();
  const SV3 ap{{(*dp)[0], (*dp)[1], (*dp)[2]}}, alp{{(*dp)[3], (*dp)[4], (*dp)[5]}};
  const SV3 lin = A_.mul(R_BP, A_.add(ap, A_.cross(alp, s.d)));
  const SV3 ang = A_.mul(R_BP, alp);
  for (int a = 0; a < 3; ++a) dl[a] = lin[a], dl[3 + a] = ang[a];
  for (int i = 0; i < static_cast<int>(s.N.size()); ++i)
    for (int k = 0; k < 6; ++k) dl[k] = dl[k] + s.N[i][k] * (*dp)[6 + i];
  return dl;
}

std::vector<ex> KaneBuilder::transform_wrench_to_parent(int cidx, const std::vector<ex>& W6) {
  const SymBody& s = body_[cidx];
  const int p = model_.bodies[cidx].parent;
  const int m_P = model_.bodies[p].n_modes();
  const SV3 f{{W6[0], W6[1], W6[2]}}, t{{W6[3], W6[4], W6[5]}};
  const SV3 fP = A_.mul(s.R_PB, f);
  const SV3 tP = A_.add(A_.mul(s.R_PB, t), A_.cross(s.d, fP));
  std::vector<ex> out(6 + m_P, ex(0));
  for (int a = 0; a < 3; ++a) out[a] = fP[a], out[3 + a] = tP[a];
  for (int i = 0; i < static_cast<int>(s.N.size()); ++i) {
    ex sum = 0;
    for (int k = 0; k < 6; ++k) sum += s.N[i][k] * W6[k];
    out[6 + i] = A_.let(sum);
  }
  return out;
}

static ex dot(const std::vector<ex>& a, const std::vector<ex>& b) {
  ex s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

std::vector<std::vector<ex>> KaneBuilder::bias_forces() {
  const int nb = static_cast<int>(model_.bodies.size());
  std::vector<std::vector<ex>> y(nb);
  for (int j = 0; j < nb; ++j) {  // y_j = g_j - h_j - M_j z_R
    const SymBody& s = body_[j];
    const int n = 6 + model_.bodies[j].n_modes();
    y[j].resize(n);
    for (int r = 0; r < n; ++r) {
      ex sum = s.g[r] - s.h[r];
      for (int a = 0; a < 3; ++a) sum -= s.Mb(r, a) * s.aR[a] + s.Mb(r, 3 + a) * s.alR[a];
      y[j][r] = A_.let(sum);
    }
  }
  return y;
}

ex KaneBuilder::applied_force(int j, int k) {
  const Body& b = model_.bodies[j];
  const int r = b.u_joint + k;
  ex f = x_.tau[r];
  C_.group = b.name;
  if (k < joint_nu(b.joint.type) && (b.joint.type == JointType::revolute || b.joint.type == JointType::prismatic)) {
    const ex kk = c(b.joint.stiffness, b.name + "_k", "N m/rad or N/m", "joint spring stiffness");
    const ex cc = c(b.joint.damping, b.name + "_c", "N m s/rad or N s/m", "joint damping");
    const ex rest = c(b.joint.rest, b.name + "_rest", "rad or m", "spring rest value");
    f -= kk * (x_.q[b.q_joint] - rest) + cc * x_.u[b.u_joint];
  }
  if (k >= joint_nu(b.joint.type)) {
    const int i = k - joint_nu(b.joint.type);
    const ex K = c(b.flex->K(i), fmt::format("{}_K{}", b.name, i + 1), "N m", "modal stiffness");
    const ex D = c(b.flex->D(i), fmt::format("{}_D{}", b.name, i + 1), "N m s", "modal damping");
    f -= K * x_.q[b.q_eta + i] + D * x_.u[b.u_eta + i];
  }
  return A_.let(f);
}

std::vector<ex> KaneBuilder::forcing() {
  const int nb = static_cast<int>(model_.bodies.size());
  std::vector<std::vector<ex>> W = bias_forces();
  std::vector<ex> F(model_.nu, ex(0));
  for (int j = nb - 1; j >= 0; --j) {
    const Body& b = model_.bodies[j];
    const auto S = motion_subspace(j);
    const auto cols = own_columns(j);
    for (std::size_t k = 0; k < cols.size(); ++k) F[cols[k]] = A_.let(applied_force(j, static_cast<int>(k)) + dot(S[k], W[j]));
    if (b.parent >= 0) {
      const auto Wp = transform_wrench_to_parent(j, {W[j].begin(), W[j].begin() + 6});
      for (std::size_t r = 0; r < Wp.size(); ++r) W[b.parent][r] = A_.let(W[b.parent][r] + Wp[r]);
    }
  }
  return F;
}

// ---------------------------------------------------------------------------
// Articulated-body form, O(n): with delta_j = body accelerations minus their
// remainders (delta_j = Xe_j delta_p + S_j udot_j), the subtree wrench of j is
// IA_j delta_j + pA_j. Inward: U = IA S, D = S^T U, r = tau' - S^T pA,
// Ia = IA - U D^-1 U^T, pa = pA + U D^-1 r, passed to the parent through
// Xe^T; outward: udot_j = D^-1 (r - U^T Xe_j delta_p).
std::vector<ex> KaneBuilder::udot_articulated(std::vector<ex>& pivots) {
  const int nb = static_cast<int>(model_.bodies.size());
  std::vector<std::vector<ex>> pA = bias_forces();
  for (auto& v : pA)
    for (auto& e : v) e = A_.let(-e);
  std::vector<SMat> IA(nb);
  for (int j = 0; j < nb; ++j) IA[j] = body_[j].Mb;
  struct Joint {
    std::vector<std::vector<ex>> U;   // (6+m) x k, by column
    SMat Dinv;                        // k x k
    std::vector<ex> r;                // k
  };
  std::vector<Joint> J(nb);
  pivots.clear();
  for (int j = nb - 1; j >= 0; --j) {
    const Body& b = model_.bodies[j];
    const auto S = motion_subspace(j);
    const int k = static_cast<int>(S.size());
    const int n = IA[j].rows;
    SMat& I = IA[j];
    for (auto& e : I.a) e = A_.let(e);
    Joint& jt = J[j];
    jt.U.assign(k, std::vector<ex>(n));
    for (int c = 0; c < k; ++c)
      for (int r = 0; r < n; ++r) {
        ex sum = 0;
        for (int t = 0; t < n; ++t) sum += I(r, t) * S[c][t];
        jt.U[c][r] = A_.let(sum);
      }
    SMat D(k, k);
    jt.r.resize(k);
    for (int c = 0; c < k; ++c) {
      for (int c2 = 0; c2 <= c; ++c2) D(c, c2) = D(c2, c) = A_.let(dot(S[c2], jt.U[c]));
      jt.r[c] = A_.let(applied_force(j, c) - dot(S[c], pA[j]));
    }
    jt.Dinv = spd_inverse(D, pivots);
    if (b.parent < 0) continue;
    // Ia = IA - U Dinv U^T (rows/cols 0-5 are all the parent sees), pa = pA + U Dinv r
    std::vector<std::vector<ex>> UD(k, std::vector<ex>(6));  // (U Dinv) by column, rows 0-5
    for (int c = 0; c < k; ++c)
      for (int r = 0; r < 6; ++r) {
        ex sum = 0;
        for (int t = 0; t < k; ++t) sum += jt.U[t][r] * jt.Dinv(t, c);
        UD[c][r] = A_.let(sum);
      }
    SMat Ia(6, 6);
    std::vector<ex> pa(6);
    for (int r = 0; r < 6; ++r) {
      for (int c = r; c < 6; ++c) {
        ex sum = I(r, c);
        for (int t = 0; t < k; ++t) sum -= UD[t][r] * jt.U[t][c];
        Ia(r, c) = Ia(c, r) = A_.let(sum);
      }
      ex sum = pA[j][r];
      for (int t = 0; t < k; ++t) sum += UD[t][r] * jt.r[t];
      pa[r] = A_.let(sum);
    }
    // Parent: IA_p += Xe^T Ia Xe, pA_p += Xe^T pa, Xe = [X6 | N] acting on the parent's (6 + m_p).
    const int np = IA[b.parent].rows;
    std::vector<std::vector<ex>> XtIa(6);  // XtIa[c] = Xe^T Ia[:, c]  (np entries)
    for (int c = 0; c < 6; ++c) {
      std::vector<ex> col(6);
      for (int r = 0; r < 6; ++r) col[r] = Ia(r, c);
      XtIa[c] = transform_wrench_to_parent(j, col);
    }
    // Xe^T Ia Xe = Xe^T (Xe^T Ia)^T: row a of (Xe^T Ia) is the np-vector over c -> XtIa[c][a]
    for (int a = 0; a < np; ++a) {
      std::vector<ex> row(6);
      for (int c = 0; c < 6; ++c) row[c] = XtIa[c][a];
      const auto t = transform_wrench_to_parent(j, row);
      for (int bb = a; bb < np; ++bb) {
        const ex v = A_.let(IA[b.parent](a, bb) + t[bb]);
        IA[b.parent](a, bb) = IA[b.parent](bb, a) = v;
      }
    }
    const auto pt = transform_wrench_to_parent(j, pa);
    for (int r = 0; r < np; ++r) pA[b.parent][r] = A_.let(pA[b.parent][r] + pt[r]);
  }
  // Outward.
  std::vector<ex> ud(model_.nu, ex(0));
  std::vector<std::vector<ex>> delta(nb);
  for (int j = 0; j < nb; ++j) {
    const Body& b = model_.bodies[j];
    const int n = IA[j].rows;
    std::vector<ex> dl = transform_motion_from_parent(j, b.parent >= 0 ? &delta[b.parent] : nullptr);
    const auto S = motion_subspace(j);
    const int k = static_cast<int>(S.size());
    const Joint& jt = J[j];
    std::vector<ex> rhs(k);
    for (int c = 0; c < k; ++c) rhs[c] = A_.let(jt.r[c] - dot(jt.U[c], dl));
    const auto cols = own_columns(j);
    for (int c = 0; c < k; ++c) {
      ex sum = 0;
      for (int t = 0; t < k; ++t) sum += jt.Dinv(c, t) * rhs[t];
      ud[cols[c]] = A_.let(sum);
    }
    for (int c = 0; c < k; ++c)
      for (int r = 0; r < n; ++r) dl[r] = dl[r] + S[c][r] * ud[cols[c]];
    for (auto& e : dl) e = A_.let(e);
    delta[j] = dl;
  }
  return ud;
}

SMat KaneBuilder::spd_inverse(const SMat& D, std::vector<ex>& pivots) {
  const int k = D.rows;
  // L D L^T, then inverse = L^-T Dg^-1 L^-1
  SMat L(k, k);
  std::vector<ex> Dg(k);
  for (int i = 0; i < k; ++i) {
    ex d = D(i, i);
    for (int t = 0; t < i; ++t) d -= L(i, t) * L(i, t) * Dg[t];
    Dg[i] = A_.let(d);
    pivots.push_back(Dg[i]);
    L(i, i) = 1;
    const ex inv = A_.let(1 / Dg[i]);
    for (int r = i + 1; r < k; ++r) {
      ex v = D(r, i);
      for (int t = 0; t < i; ++t) v -= L(r, t) * L(i, t) * Dg[t];
      L(r, i) = A_.let(v * inv);
    }
  }
  // Linv (unit lower)
  SMat Li(k, k);
  for (int c = 0; c < k; ++c) {
    Li(c, c) = 1;
    for (int r = c + 1; r < k; ++r) {
      ex v = 0;
      for (int t = c; t < r; ++t) v -= L(r, t) * Li(t, c);
      Li(r, c) = A_.let(v);
    }
  }
  SMat inv(k, k);
  for (int r = 0; r < k; ++r)
    for (int c = r; c < k; ++c) {
      ex v = 0;
      for (int t = std::max(r, c); t < k; ++t) v += Li(t, r) * Li(t, c) / Dg[t];
      inv(r, c) = inv(c, r) = A_.let(v);
    }
  return inv;
}

// ---------------------------------------------------------------------------
SMat KaneBuilder::mass_matrix() {
  const int nb = static_cast<int>(model_.bodies.size());
  const int nu = model_.nu;
  SMat M(nu, nu);
  // Composite inertias, leaves first.
  Ic_.assign(nb, SMat());
  for (int j = 0; j < nb; ++j) Ic_[j] = body_[j].Mb;
  for (int j = nb - 1; j >= 0; --j) {
    const int p = model_.bodies[j].parent;
    SMat& I = Ic_[j];
    for (auto& e : I.a) e = A_.let(e);
    if (p < 0) continue;
    const SymBody& s = body_[j];
    // Rigid part: m' = m, S' = R S + m d, J' = R J R^T - d^x S'^x... as the 6x6 spatial transform
    const ex mass = I(0, 0);
    const SV3 S{{I(5, 1), I(3, 2), I(4, 0)}};  // from I(3..5, 0..2) = S^x
    SM3 J;
    for (int a = 0; a < 3; ++a)
      for (int cc = 0; cc < 3; ++cc) J(a, cc) = I(3 + a, 3 + cc);
    const SV3 RS = A_.mul(s.R_PB, S);
    const SV3 Sp = A_.add(RS, A_.scale(mass, s.d));
    const SM3 RJ = A_.mul(s.R_PB, J);
    SM3 RJRt;
    for (int a = 0; a < 3; ++a)
      for (int cc = a; cc < 3; ++cc) {
        ex sum = 0;
        for (int t = 0; t < 3; ++t) sum += RJ(a, t) * s.R_PB(cc, t);
        RJRt(a, cc) = RJRt(cc, a) = A_.let(sum);
      }
    // J_p = R J R^T - d^x RS^x - RS^x d^x - m d^x d^x, symmetric
    const SM3 dx = Alg::skew(s.d), RSx = Alg::skew(RS);
    SMat& Ip = Ic_[p];
    for (int a = 0; a < 3; ++a)
      for (int cc = a; cc < 3; ++cc) {
        ex sum = RJRt(a, cc);
        for (int t = 0; t < 3; ++t) sum -= dx(a, t) * RSx(t, cc) + RSx(a, t) * dx(t, cc) + mass * dx(a, t) * dx(t, cc);
        const ex v = A_.let(Ip(3 + a, 3 + cc) + sum);
        Ip(3 + a, 3 + cc) = v;
        Ip(3 + cc, 3 + a) = v;
      }
    for (int a = 0; a < 3; ++a) Ip(a, a) = A_.let(Ip(a, a) + mass);
    const SM3 Spx = Alg::skew(Sp);
    for (int a = 0; a < 3; ++a)
      for (int cc = 0; cc < 3; ++cc) {
        if (Spx(a, cc).is_zero()) continue;
        Ip(3 + a, cc) = A_.let(Ip(3 + a, cc) + Spx(a, cc));
        Ip(cc, 3 + a) = A_.let(Ip(cc, 3 + a) + Spx(a, cc));
      }
    // Node coupling of a child at a node of a flexible parent: with
    // Xe = [X6 | N], add X6^T I6 N (6 x m_p) and N^T I6 N (m_p x m_p).
    const int m_P = static_cast<int>(s.N.size());
    if (m_P > 0) {
      std::vector<std::vector<ex>> I6N(m_P);  // I6 * N_i
      for (int i = 0; i < m_P; ++i) {
        I6N[i].resize(6);
        for (int r = 0; r < 6; ++r) {
          ex sum = 0;
          for (int k = 0; k < 6; ++k) sum += I(r, k) * s.N[i][k];
          I6N[i][r] = A_.let(sum);
        }
      }
      for (int i = 0; i < m_P; ++i) {
        const auto top = transform_wrench_to_parent(j, I6N[i]);  // X6^T (I6 N_i), plus N^T I6 N_i below
        for (int r = 0; r < 6; ++r) {
          Ip(r, 6 + i) = A_.let(Ip(r, 6 + i) + top[r]);
          Ip(6 + i, r) = Ip(r, 6 + i);
        }
        for (int k = 0; k < m_P; ++k) Ip(6 + k, 6 + i) = A_.let(Ip(6 + k, 6 + i) + top[6 + k]);
      }
    }
  }
  // Columns: f = Ic_j S_j[:, s]; M(own_j, s) = S_j^T f; then walk to the root.
  for (int j = 0; j < nb; ++j) {
    const auto S = motion_subspace(j);
    const auto cols = own_columns(j);
    const SMat& I = Ic_[j];
    for (std::size_t k = 0; k < cols.size(); ++k) {
      std::vector<ex> f(I.rows);
      for (int r = 0; r < I.rows; ++r) {
        ex sum = 0;
        for (int cc = 0; cc < I.cols; ++cc) sum += I(r, cc) * S[k][cc];
        f[r] = A_.let(sum);
      }
      for (std::size_t k2 = 0; k2 <= k; ++k2) {
        M(cols[k], cols[k2]) = M(cols[k2], cols[k]) = A_.let(dot(S[k2], f));
      }
      int i = j;
      std::vector<ex> fi = f;
      while (model_.bodies[i].parent >= 0) {
        const int p = model_.bodies[i].parent;
        fi = transform_wrench_to_parent(i, {fi.begin(), fi.begin() + 6});
        const auto Sp = motion_subspace(p);
        const auto pcols = own_columns(p);
        for (std::size_t kp = 0; kp < pcols.size(); ++kp)
          M(pcols[kp], cols[k]) = M(cols[k], pcols[kp]) = A_.let(dot(Sp[kp], fi));
        i = p;
      }
    }
  }
  return M;
}

// ---------------------------------------------------------------------------
std::vector<ex> KaneBuilder::solve(SMat H, std::vector<ex> b, std::vector<ex>& pivots) {
  const int n = H.rows;
  // lambda: parent of each dof in the dof tree
  std::vector<int> lambda(n, -1);
  for (const Body& bd : model_.bodies) {
    const int nown = joint_nu(bd.joint.type) + bd.n_modes();
    if (nown == 0) continue;
    int prev = -1;
    if (bd.parent >= 0) {
      const auto& ch = model_.bodies[bd.parent].chain_u;
      prev = ch.empty() ? -1 : ch.back();
    }
    for (int k = 0; k < nown; ++k) {
      lambda[bd.u_joint + k] = prev;
      prev = bd.u_joint + k;
    }
  }
  for (int k = n - 1; k >= 0; --k) {
    int i = lambda[k];
    const ex inv = A_.let(1 / H(k, k));
    while (i != -1) {
      const ex a = A_.let(H(k, i) * inv);
      int jj = i;
      while (jj != -1) {
        H(i, jj) = A_.let(H(i, jj) - a * H(k, jj));
        jj = lambda[jj];
      }
      H(k, i) = a;
      i = lambda[i];
    }
  }
  pivots.resize(n);
  for (int k = 0; k < n; ++k) pivots[k] = H(k, k);
  for (int i = n - 1; i >= 0; --i)
    for (int jj = lambda[i]; jj != -1; jj = lambda[jj]) b[jj] = A_.let(b[jj] - H(i, jj) * b[i]);
  for (int i = 0; i < n; ++i) b[i] = A_.let(b[i] / H(i, i));
  for (int i = 0; i < n; ++i)
    for (int jj = lambda[i]; jj != -1; jj = lambda[jj]) b[i] = A_.let(b[i] - H(i, jj) * b[jj]);
  return b;
}

// ---------------------------------------------------------------------------
std::vector<ex> KaneBuilder::reactions(const std::vector<ex>& udot) {
  const int nb = static_cast<int>(model_.bodies.size());
  // delta_j = acceleration minus remainder: delta_c = Xe_c delta_p + S_c udot_own
  std::vector<std::vector<ex>> delta(nb), W(nb);
  for (int j = 0; j < nb; ++j) {
    const Body& b = model_.bodies[j];
    const SymBody& s = body_[j];
    const int m = b.n_modes();
    std::vector<ex> dl = transform_motion_from_parent(j, b.parent >= 0 ? &delta[b.parent] : nullptr);
    const auto S = motion_subspace(j);
    const auto cols = own_columns(j);
    for (std::size_t k = 0; k < cols.size(); ++k)
      for (int r = 0; r < 6 + m; ++r) dl[r] = dl[r] + S[k][r] * udot[cols[k]];
    for (auto& e : dl) e = A_.let(e);
    delta[j] = dl;
    // wrench = M_b (delta + z_R) + h - g, rows 0-5
    W[j].resize(6);
    for (int r = 0; r < 6; ++r) {
      ex sum = s.h[r] - s.g[r];
      for (int k = 0; k < 6 + m; ++k) {
        ex z = dl[k];
        if (k < 3) z = z + s.aR[k];
        else if (k < 6) z = z + s.alR[k - 3];
        sum += s.Mb(r, k) * z;
      }
      W[j][r] = A_.let(sum);
    }
  }
  for (int j = nb - 1; j >= 0; --j) {
    const int p = model_.bodies[j].parent;
    if (p < 0) continue;
    const auto Wp = transform_wrench_to_parent(j, W[j]);
    for (int r = 0; r < 6; ++r) W[p][r] = A_.let(W[p][r] + Wp[r]);
  }
  std::vector<ex> out;
  for (int j = 0; j < nb; ++j) out.insert(out.end(), W[j].begin(), W[j].end());
  return out;
}

// ---------------------------------------------------------------------------
ex KaneBuilder::kinetic_energy() {
  ex T = 0;
  for (std::size_t j = 0; j < model_.bodies.size(); ++j) {
    const SymBody& s = body_[j];
    const int n = s.Mb.rows;
    std::vector<ex> z(n);
    for (int a = 0; a < 3; ++a) z[a] = s.v[a], z[3 + a] = s.w[a];
    for (int i = 0; i + 6 < n; ++i) z[6 + i] = s.eta_dot[i];
    ex Tj = 0;
    for (int r = 0; r < n; ++r) {
      ex row = 0;
      for (int k = 0; k < n; ++k) row += s.Mb(r, k) * z[k];
      Tj += z[r] * A_.let(row);
    }
    T += A_.let(Tj);
  }
  return A_.let(T / 2);
}

ex KaneBuilder::potential_energy() {
  ex V = 0;
  C_.group = "model";
  const SV3 g_N = cvec(model_.g_N, "gravity", "m/s^2", "gravity in N");
  for (std::size_t j = 0; j < model_.bodies.size(); ++j) {
    const Body& b = model_.bodies[j];
    const SymBody& s = body_[j];
    if (!model_.g_N.isZero()) {
      // -g . (m r_O + R_NB S)
      SV3 S{{s.Mb(5, 1), s.Mb(3, 2), s.Mb(4, 0)}};  // from rows 3-5 = S^x
      const SV3 RS = A_.mul(s.R_NB, S);
      for (int a = 0; a < 3; ++a) V -= g_N[a] * (s.Mb(0, 0) * s.r_NO[a] + RS[a]);
    }
    C_.group = b.name;
    if (b.joint.type == JointType::revolute || b.joint.type == JointType::prismatic) {
      const ex kk = c(b.joint.stiffness, b.name + "_k", "N m/rad or N/m", "joint spring stiffness");
      const ex rest = c(b.joint.rest, b.name + "_rest", "rad or m", "spring rest value");
      const ex dq = A_.let(x_.q[b.q_joint] - rest);
      V += kk * dq * dq / 2;
    }
    for (int i = 0; i < b.n_modes(); ++i) {
      const ex K = c(b.flex->K(i), fmt::format("{}_K{}", b.name, i + 1), "N m", "modal stiffness");
      V += K * s.eta[i] * s.eta[i] / 2;
    }
    V = A_.let(V);
  }
  return V;
}

std::vector<ex> KaneBuilder::momentum() {
  SV3 p, H;
  for (std::size_t j = 0; j < model_.bodies.size(); ++j) {
    const SymBody& s = body_[j];
    const int n = s.Mb.rows;
    std::vector<ex> z(n);
    for (int a = 0; a < 3; ++a) z[a] = s.v[a], z[3 + a] = s.w[a];
    for (int i = 0; i + 6 < n; ++i) z[6 + i] = s.eta_dot[i];
    std::vector<ex> h(6);
    for (int r = 0; r < 6; ++r) {
      ex row = 0;
      for (int k = 0; k < n; ++k) row += s.Mb(r, k) * z[k];
      h[r] = A_.let(row);
    }
    const SV3 pN = A_.mul(s.R_NB, SV3{{h[0], h[1], h[2]}});
    const SV3 HN = A_.add(A_.cross(s.r_NO, pN), A_.mul(s.R_NB, SV3{{h[3], h[4], h[5]}}));
    p = A_.add(p, pN);
    H = A_.add(H, HN);
  }
  return {p[0], p[1], p[2], H[0], H[1], H[2]};
}

std::vector<ex> KaneBuilder::qdot() {
  std::vector<ex> qd(model_.nq, ex(0));
  for (const Body& b : model_.bodies) {
    switch (b.joint.type) {
      case JointType::revolute:
      case JointType::prismatic: qd[b.q_joint] = x_.u[b.u_joint]; break;
      case JointType::fixed: break;
      case JointType::free: {
        const int q0 = b.q_joint, u0 = b.u_joint;
        const ex w = x_.q[q0 + 3], xq = x_.q[q0 + 4], y = x_.q[q0 + 5], z = x_.q[q0 + 6];
        const ex inv2 = A_.let(1 / (w * w + xq * xq + y * y + z * z));
        // R(quat/|quat|) v: the quadratic form of R divided by |quat|^2
        SM3 R;
        R(0, 0) = w * w + xq * xq - y * y - z * z, R(0, 1) = 2 * (xq * y - w * z), R(0, 2) = 2 * (xq * z + w * y);
        R(1, 0) = 2 * (xq * y + w * z), R(1, 1) = w * w - xq * xq + y * y - z * z, R(1, 2) = 2 * (y * z - w * xq);
        R(2, 0) = 2 * (xq * z - w * y), R(2, 1) = 2 * (y * z + w * xq), R(2, 2) = w * w - xq * xq - y * y + z * z;
        for (int r = 0; r < 3; ++r) {
          ex sum = 0;
          for (int k = 0; k < 3; ++k) sum += A_.let(R(r, k)) * x_.u[u0 + k];
          qd[q0 + r] = A_.let(sum * inv2);
        }
        const ex wx = x_.u[u0 + 3], wy = x_.u[u0 + 4], wz = x_.u[u0 + 5];
        qd[q0 + 3] = A_.let((-xq * wx - y * wy - z * wz) / 2);
        qd[q0 + 4] = A_.let((w * wx + y * wz - z * wy) / 2);
        qd[q0 + 5] = A_.let((w * wy - xq * wz + z * wx) / 2);
        qd[q0 + 6] = A_.let((w * wz + xq * wy - y * wx) / 2);
        break;
      }
    }
    for (int i = 0; i < b.n_modes(); ++i) qd[b.q_eta + i] = x_.u[b.u_eta + i];
  }
  return qd;
}

}  // namespace kanegen::gen
