// Symbolic outward pass (dynamics/kinematics.hpp has the same recursion in
// numbers): for child B of parent P through joint frame J,
//   R_PB = R_PJ R_JB,   p_PO_P = p_PJ + e,   w_B = R_BP (w_P + w_J + w_rel),
//   v_O_B = R_BP (v_P + w_P x p_PO_P + v_rel),  and the remainder accelerations.
#include <fmt/format.h>

#include <stdexcept>
#include <utility>

#include "codegen/kane_context.hpp"
#include "model/joints/joint_kinematics.hpp"

namespace kanegen::codegen {

using namespace GiNaC;

static const char* kAxis[3] = {"x", "y", "z"};

namespace {

/// sin and cos of a joint coordinate or angle: from the function's batch of joint angles (Program::sincos) when
/// it reads no temporary (the state, a prescribed angle's prelude value); otherwise the library's, bound here.
std::pair<ex, ex> joint_sin_cos(KaneContext& ctx, const ex& angle) {
  if (!ctx.P.reads_temporary(angle)) return ctx.P.sincos(angle);
  return {ctx.A.let(sin(angle)), ctx.A.let(cos(angle))};
}

/// Q^T Rz(z) Ry(y) Rx(x) Q: the misalignment of body j's joint frame (runtime
/// parameters, model axes) in the generator's frame B' (Q = R_BB').
SM3 misalignment_rotation(KaneContext& ctx, int j) {
  Alg& A = ctx.A;
  const std::string& n = ctx.model.bodies[j].name;
  ex c[3], s[3];
  for (int a = 0; a < 3; ++a) {
    const ex th = ctx.param(ParameterKind::misalignment, j, a).value_or(ex(0));
    c[a] = A.let(cos(th)), s[a] = A.let(sin(th));
  }
  SM3 Rx = SM3::identity(), Ry = SM3::identity(), Rz = SM3::identity();
  Rx(1, 1) = c[0], Rx(1, 2) = -s[0], Rx(2, 1) = s[0], Rx(2, 2) = c[0];
  Ry(0, 0) = c[1], Ry(0, 2) = s[1], Ry(2, 0) = -s[1], Ry(2, 2) = c[1];
  Rz(0, 0) = c[2], Rz(0, 1) = -s[2], Rz(1, 0) = s[2], Rz(1, 1) = c[2];
  const SM3 R = A.mul(Rz, A.mul(Ry, Rx));
  const Mat3 Q = ctx.R_BBp.empty() ? Mat3::Identity() : ctx.R_BBp[j];
  if (Q.isIdentity(0.0)) return R;
  const SM3 Qs = ctx.cmat(Q, n + "_R_BBp", "", "the generator's body axes in the model's");
  return A.mul(Qs.transpose(), A.mul(R, Qs));
}

/// v with round-off residues (entries below 1e-15 of its largest) set to 0: the joint-local offset of
/// joint_frames.hpp, (a, 0, d), keeps its zero
Vec3 snapped(Vec3 v) {
  snap_roundoff_residues(v);
  return v;
}

/// Qp^T p: body j's joint origin (runtime parameters, the parent's model axes) in the parent's frame P'.
SV3 joint_position(KaneContext& ctx, int j) {
  const Body& b = ctx.model.bodies[j];
  const Mat3 Qp = ctx.R_BBp.empty() || b.parent < 0 ? Mat3::Identity() : ctx.R_BBp[b.parent];
  const Vec3 p0 = Qp * b.joint.p_PJ;  // the nominal position in the parent's model axes
  SV3 p;
  for (int a = 0; a < 3; ++a)
    p[a] = ctx.param(ParameterKind::position, j, a)
               .value_or(ctx.c(p0(a), fmt::format("{}_p_PJ_model_{}", b.name, kAxis[a]), "m", "joint origin, parent's model axes"));
  if (Qp.isIdentity(0.0)) return p;
  SM3 Qt;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Qt(r, c) = ctx.c(Qp(c, r), fmt::format("{}_R_PpP_{}{}", b.name, r, c), "", "parent's model axes in its generator frame");
  return ctx.A.mul(Qt, p);
}

}  // namespace

SV3 KaneContext::gravity(double sign, const std::string& n, const std::string& what) {
  C.group = "model";
  SV3 g = cvec(sign * model.g_N, n, "m/s^2", what);
  for (int a = 0; a < 3; ++a)
    if (auto p = param(ParameterKind::gravity, -1, a)) g[a] = sign * *p;
  return g;
}

SV3 KaneContext::cvec(const Vec3& v, const std::string& n, const std::string& unit, const std::string& what) {
  SV3 r;
  for (int i = 0; i < 3; ++i) r[i] = c(v(i), n + "_" + kAxis[i], unit, what + " " + kAxis[i]);
  return r;
}

SM3 KaneContext::cmat(const Mat3& m, const std::string& n, const std::string& unit, const std::string& what,
                      bool symmetric) {
  SM3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const int a = symmetric ? std::min(i, j) : i, b = symmetric ? std::max(i, j) : j;
      r(i, j) = c(m(a, b), fmt::format("{}_{}{}", n, kAxis[a], kAxis[b]), unit, what);
    }
  return r;
}

std::array<ex, 3> KaneContext::motion(int j) {
  if (auto it = motion_symbols.find(j); it != motion_symbols.end()) return it->second;
  const Body& b = model.bodies[j];
  const PrescribedMotion& m = *b.joint.motion;
  const std::string f = "f_" + b.name, fd = "f_dot_" + b.name, fdd = "f_ddot_" + b.name;
  C.group = b.name;
  const char* unit = b.joint.type == JointType::revolute ? "rad" : "m";
  auto arg = [&](double v, const std::string& what_name, const std::string& u, const std::string& what) {
    OpCount unused;
    return print_cpp(c(v, b.name + "_motion_" + what_name, u, what), unused);
  };
  std::string text = fmt::format("double {}, {}, {}; ", f, fd, fdd);
  switch (m.kind) {
    case MotionKind::polynomial: {
      std::string coeffs;
      for (std::size_t i = 0; i < m.coefficients.size(); ++i)
        coeffs += (i ? ", " : "") + arg(m.coefficients[i], fmt::format("c{}", i), fmt::format("{}/s^{}", unit, i),
                                         fmt::format("prescribed motion: polynomial coefficient {}", i));
      text += fmt::format("const double c_{}[] = {{{}}}; motion_polynomial(t, c_{}, {}, {}, {}, {});", b.name, coeffs,
                          b.name, m.coefficients.size(), f, fd, fdd);
      break;
    }
    case MotionKind::sine:
      text += fmt::format("motion_sine(t, {}, {}, {}, {}, {}, {}, {});",
                          arg(m.offset, "offset", unit, "prescribed motion: sine offset"),
                          arg(m.amplitude, "amplitude", unit, "prescribed motion: sine amplitude"),
                          arg(m.frequency_hz, "frequency", "Hz", "prescribed motion: sine frequency"),
                          arg(m.phase, "phase", "rad", "prescribed motion: sine phase"), f, fd, fdd);
      break;
    case MotionKind::spinup:
      text += fmt::format("motion_spinup(t, {}, {}, {}, {}, {}, {});",
                          arg(m.rate, "rate", std::string(unit) + "/s", "prescribed motion: spin-up final rate"),
                          arg(m.duration, "duration", "s", "prescribed motion: spin-up duration"),
                          arg(m.start, "start", unit, "prescribed motion: spin-up start value"), f, fd, fdd);
      break;
  }
  P.prelude(text, {f, fd, fdd});
  const std::array<ex, 3> syms = {GiNaC::symbol(f), GiNaC::symbol(fd), GiNaC::symbol(fdd)};
  motion_symbols[j] = syms;
  return syms;
}

void compute_kinematics(KaneContext& ctx, bool with_velocity) {
  Alg& A = ctx.A;
  const Model& model = ctx.model;
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const int j = static_cast<int>(i);
    const Body& b = model.bodies[i];
    SymBodyWorkspace& s = ctx.body[i];
    ctx.C.group = b.name;
    const std::string& n = b.name;
    ctx.P.section(fmt::format("body {}: outward pass ({})", n, with_velocity ? "velocities" : "positions"));
    const int m = b.n_modes();
    s.eta.clear(), s.eta_dot.clear();
    for (int mode = 0; mode < m; ++mode) {
      s.eta.push_back(ctx.x.q[b.q_eta + mode]);
      s.eta_dot.push_back(ctx.x.u[b.u_eta + mode]);
    }
    const bool has_parent = b.parent >= 0;
    const SymBodyWorkspace* p = has_parent ? &ctx.body[b.parent] : nullptr;
    const SV3 zero;
    const SV3 w_P = has_parent ? p->w_B : zero, v_P = has_parent ? p->v_O_B : zero;
    SV3 minus_g;
    if (!has_parent && with_velocity && ctx.gravity_in_base_acceleration && ctx.has_gravity()) {
      minus_g = ctx.gravity(-1.0, "minus_gravity", "-gravity in N: the ground's fictitious acceleration");
      ctx.C.group = b.name;
    }
    const SV3 aR_P = has_parent ? p->a_R_B : minus_g, alR_P = has_parent ? p->alpha_R_B : zero;

    // Joint frame; with a screw (joint_frames.hpp) R_PJ is the frame in the parent's axes turned by R_PS.
    const double beta = i < ctx.screw_angle.size() ? ctx.screw_angle[i] : 0.0;
    s.screw = beta != 0.0;
    if (s.screw && b.joint.node >= 0)  // joint_frames.cpp turns only children of re-chosen (rigid) parents
      throw std::logic_error("generator: a screw turn on a joint at a flexible parent's node (" + n + ")");
    s.R_PS = SM3::identity();
    SM3 R_PJ;
    if (s.screw) {
      const Mat3 R_SJ = rot_z(beta).transpose() * b.joint.R_PJ;  // Rx(alpha), to rounding
      s.R_PS = ctx.cmat(rot_z(beta), n + "_R_PS", "",
                        "the parent's axes turned about their z onto the common normal to the joint axis");
      R_PJ = ctx.cmat(rot_x(std::atan2(R_SJ(2, 1), R_SJ(1, 1))), n + "_R_SJ", "",
                      "joint frame orientation in the parent's turned axes (joint_frames.hpp)");
    } else {
      R_PJ = ctx.cmat(b.joint.R_PJ, n + "_R_PJ", "", "joint frame orientation in the parent");
    }
    // runtime parameters of the joint's placement (model/parameters.hpp), given in the model's frames
    const bool misaligned = ctx.param(ParameterKind::misalignment, static_cast<int>(j), 0) ||
                            ctx.param(ParameterKind::misalignment, static_cast<int>(j), 1) ||
                            ctx.param(ParameterKind::misalignment, static_cast<int>(j), 2);
    const bool moved = ctx.param(ParameterKind::position, static_cast<int>(j), 0) ||
                       ctx.param(ParameterKind::position, static_cast<int>(j), 1) ||
                       ctx.param(ParameterKind::position, static_cast<int>(j), 2);
    if (misaligned) R_PJ = A.mul(R_PJ, misalignment_rotation(ctx, static_cast<int>(j)));
    SV3 p_PJ;
    SV3 w_J, w_J_dot_R, v_node, a_node_R;
    std::vector<SV3> H_cols, Phi_cols;  // per parent mode
    const int m_P = has_parent ? model.bodies[b.parent].n_modes() : 0;
    if (b.joint.node >= 0) {
      const FlexibleData& pf = *model.bodies[b.parent].flex;
      const int node = b.joint.node;
      const std::string nn = fmt::format("{}_node{}", n, pf.nodes[node].id);
      for (int mode = 0; mode < m_P; ++mode) {
        Phi_cols.push_back(ctx.cvec(pf.Phi.block(3 * node, mode, 3, 1), fmt::format("{}_Phi{}", nn, mode + 1), "m",
                                  fmt::format("translational shape of mode {} at the attachment node", mode + 1)));
      }
      std::vector<SV3> Psi_cols;
      for (int mode = 0; mode < m_P; ++mode)
        Psi_cols.push_back(ctx.cvec(pf.Psi.block(3 * node, mode, 3, 1), fmt::format("{}_Psi{}", nn, mode + 1), "rad",
                                  fmt::format("rotational shape of mode {} at the attachment node", mode + 1)));
      // g = Psi eta / 2, C(g) = I + 2/(1+g.g) (g^x + g^x g^x)
      SV3 g;
      for (int a = 0; a < 3; ++a) {
        ex sum = 0;
        for (int mode = 0; mode < m_P; ++mode) sum += Psi_cols[mode][a] * p->eta[mode];
        g[a] = A.let(sum / 2);
      }
      const ex denom = A.let(1 + g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
      const ex two_over = A.let(2 / denom);
      const SM3 G = Alg::skew(g);
      SM3 Cg;
      for (int r = 0; r < 3; ++r)
        for (int cc = 0; cc < 3; ++cc) {
          ex gg = 0;
          for (int t = 0; t < 3; ++t) gg += G(r, t) * G(t, cc);
          Cg(r, cc) = A.let((r == cc ? 1 : 0) + two_over * (G(r, cc) + gg));
        }
      R_PJ = A.mul(Cg, R_PJ);
      const SV3 rho = ctx.cvec(pf.nodes[node].rho_B, nn + "_rho", "m", "attachment node position in the parent");
      // Foreshortening: p_PJ gains 1/2 eta^T Gamma^a eta; the node's shape
      // becomes Phi~ = Phi + G(eta), row a of G = (Gamma^a eta)^T.
      std::vector<SV3> Gcols(m_P);  // G(eta) by column
      SV3 half_gamma;
      if (pf.has_second_order(node))
        for (int a = 0; a < 3; ++a) {
          const MatX& G = pf.Gamma[node][a];
          if (G.size() == 0) continue;
          ex quad = 0;
          for (int i = 0; i < m_P; ++i) {
            ex row = 0;
            for (int l = 0; l < m_P; ++l)
              row += ctx.c(G(std::min(i, l), std::max(i, l)),
                           fmt::format("{}_Gamma{}_{}_{}", nn, kAxis[a], std::min(i, l) + 1, std::max(i, l) + 1), "1/m",
                           "second-order (foreshortening) coefficient of the attachment node") *
                     p->eta[l];
            Gcols[i][a] = A.let(row);
            quad += row * p->eta[i];
          }
          half_gamma[a] = A.let(quad / 2);
        }
      for (int a = 0; a < 3; ++a) {
        ex sum = rho[a] + half_gamma[a];
        for (int mode = 0; mode < m_P; ++mode) sum += Phi_cols[mode][a] * p->eta[mode];
        p_PJ[a] = A.let(sum);
      }
      for (int mode = 0; mode < m_P; ++mode) Phi_cols[mode] = A.add(Phi_cols[mode], Gcols[mode]);
      if (with_velocity && pf.has_second_order(node))
        for (int a = 0; a < 3; ++a) {  // [eta_dot^T Gamma^a eta_dot]_a
          const MatX& G = pf.Gamma[node][a];
          if (G.size() == 0) continue;
          ex sum = 0;
          for (int i = 0; i < m_P; ++i)
            for (int l = 0; l < m_P; ++l)
              sum += ctx.c(G(std::min(i, l), std::max(i, l)),
                           fmt::format("{}_Gamma{}_{}_{}", nn, kAxis[a], std::min(i, l) + 1, std::max(i, l) + 1), "1/m",
                           "second-order (foreshortening) coefficient of the attachment node") *
                     p->eta_dot[i] * p->eta_dot[l];
          a_node_R[a] = A.let(sum);
        }
      // H = (I + g^x) Psi / (1 + g.g): w_J = H eta_dot_P
      const ex inv = A.let(1 / denom);
      for (int mode = 0; mode < m_P; ++mode) {
        SV3 h;
        const SV3 gx = A.cross(g, Psi_cols[mode]);
        for (int a = 0; a < 3; ++a) h[a] = A.let((Psi_cols[mode][a] + gx[a]) * inv);
        H_cols.push_back(h);
      }
      if (with_velocity) {
        for (int a = 0; a < 3; ++a) {
          ex wj = 0, vn = 0;
          for (int mode = 0; mode < m_P; ++mode) {
            wj += H_cols[mode][a] * p->eta_dot[mode];
            vn += Phi_cols[mode][a] * p->eta_dot[mode];
          }
          w_J[a] = A.let(wj);
          v_node[a] = A.let(vn);
        }
        SV3 g_dot;
        for (int a = 0; a < 3; ++a) {
          ex sum = 0;
          for (int mode = 0; mode < m_P; ++mode) sum += Psi_cols[mode][a] * p->eta_dot[mode];
          g_dot[a] = A.let(sum / 2);
        }
        const ex f = A.let(-2 * A.dot(g, g_dot) * inv);
        w_J_dot_R = A.scale(f, w_J);
      }
    } else if (moved) {
      p_PJ = joint_position(ctx, static_cast<int>(j));
    } else {
      p_PJ = ctx.cvec(b.joint.p_PJ, n + "_p_PJ", "m", "joint frame origin in the parent");
    }

    // Joint motion; a prescribed joint's coordinate and rate are its motion at t.
    // Everything relative to the joint is formed in J components, where the
    // generator's frames make the joint axis a coordinate axis (joint_frames.hpp),
    // and turned into B components by R_JB^T once.
    SM3 R_JB = SM3::identity();
    SV3 e_J;                   // O_B - O_J, J components
    SV3 e_dot_B, w_rel_B;      // rates of e and of B relative to J, B components
    SV3 bias_w_B, bias_v_B;    // the motion subspace's rate S_dot u (joint module joints), B components
    s.S_joint.clear();
    const SV3 axis = ctx.cvec(b.joint.axis_J, n + "_axis", "", "joint axis");
    ex q_j = 0, u_j = 0, f_ddot = 0;
    if (b.joint.prescribed()) {
      const auto f = ctx.motion(j);
      q_j = f[0], u_j = f[1], f_ddot = f[2];
    } else if (b.joint.type == JointType::revolute || b.joint.type == JointType::prismatic) {
      q_j = ctx.x.q[b.q_joint], u_j = ctx.x.u[b.u_joint];
    }
    switch (b.joint.type) {
      case JointType::revolute: {
        const double offset = i < ctx.angle_offset.size() ? ctx.angle_offset[i] : 0.0;
        const ex angle = q_j + ctx.c(offset, n + "_angle_offset", "rad",
                                     "joint angle offset of the generator's body frame (joint_frames.hpp)");
        const auto [sq, cq] = joint_sin_cos(ctx, angle);
        // Rot(a, th) = a a^T + cos th (I - a a^T) + sin th a^x
        const Eigen::Matrix3d aa = b.joint.axis_J * b.joint.axis_J.transpose();
        const SM3 Ax = Alg::skew(axis);
        for (int r = 0; r < 3; ++r)
          for (int cc = 0; cc < 3; ++cc) {
            const int lo = std::min(r, cc), hi = std::max(r, cc);
            const ex aa_rc =
                ctx.c(aa(r, cc), fmt::format("{}_axis_aa_{}{}", n, kAxis[lo], kAxis[hi]), "", "axis outer product");
            const ex one_minus = ctx.c((r == cc ? 1.0 : 0.0) - aa(r, cc),
                                     fmt::format("{}_axis_Iaa_{}{}", n, kAxis[lo], kAxis[hi]), "",
                                     "I - axis outer product");
            R_JB(r, cc) = A.let(aa_rc + cq * one_minus + sq * Ax(r, cc));
          }
        if (with_velocity) w_rel_B = A.scale(u_j, axis);  // R_JB^T a = a
        break;
      }
      case JointType::prismatic:
        e_J = A.scale(q_j, axis);
        if (with_velocity) e_dot_B = A.scale(u_j, axis);
        break;
      case JointType::fixed: break;
      default: {
        // every other joint type: the joint module's kinematics, in symbols (the generic engine runs the same template in numbers)
        const JointTraits& jt = joint_traits(b.joint.type);
        std::vector<ex> qj(jt.nq()), uj(jt.nu());
        for (int k = 0; k < jt.nq(); ++k) qj[k] = ctx.x.q[b.q_joint + k];
        for (int k = 0; k < jt.nu(); ++k) uj[k] = ctx.x.u[b.u_joint + k];
        std::vector<joints::Vec<ex>> axes;
        for (std::size_t k = 0; k < b.primitives.size(); ++k) {
          const SV3 a = ctx.cvec(b.primitives[k].axis, fmt::format("{}_axis{}", n, k + 1), "",
                                 fmt::format("joint axis {}", k + 1));
          axes.push_back({a[0], a[1], a[2]});
        }
        const auto jm = joints::joint_motion<ex>(b.primitives, axes, jt.nu(), qj.data(), uj.data(), with_velocity,
                                                 [&](const ex& x) { return A.let(x); },
                                                 [&](const ex& x) { return joint_sin_cos(ctx, x); });
        for (int r = 0; r < 3; ++r) {
          for (int cc = 0; cc < 3; ++cc) R_JB(r, cc) = jm.R_JB[r][cc];
          e_J[r] = jm.e_J[r];
          if (with_velocity) {
            e_dot_B[r] = jm.e_dot_B[r], w_rel_B[r] = jm.w_rel_B[r];
            bias_w_B[r] = jm.bias_w_B[r], bias_v_B[r] = jm.bias_v_B[r];
          }
        }
        for (int c = 0; c < jt.nu(); ++c)
          s.S_joint.push_back({jm.Sv[c][0], jm.Sv[c][1], jm.Sv[c][2], jm.Sw[c][0], jm.Sw[c][1], jm.Sw[c][2]});
        break;
      }
      case JointType::free: {
        const auto& q = ctx.x.q;
        const int q0 = b.q_joint;
        const ex inv_norm = A.let(1 / sqrt(q[q0 + 3] * q[q0 + 3] + q[q0 + 4] * q[q0 + 4] + q[q0 + 5] * q[q0 + 5] +
                                           q[q0 + 6] * q[q0 + 6]));
        const ex w = A.let(q[q0 + 3] * inv_norm), xq = A.let(q[q0 + 4] * inv_norm), y = A.let(q[q0 + 5] * inv_norm),
                 z = A.let(q[q0 + 6] * inv_norm);
        const ex xx = A.let(xq * xq), yy = A.let(y * y), zz = A.let(z * z);
        const ex xy = A.let(xq * y), xz = A.let(xq * z), yz = A.let(y * z);
        const ex wx = A.let(w * xq), wy = A.let(w * y), wz = A.let(w * z);
        R_JB(0, 0) = A.let(1 - 2 * (yy + zz)), R_JB(0, 1) = A.let(2 * (xy - wz)), R_JB(0, 2) = A.let(2 * (xz + wy));
        R_JB(1, 0) = A.let(2 * (xy + wz)), R_JB(1, 1) = A.let(1 - 2 * (xx + zz)), R_JB(1, 2) = A.let(2 * (yz - wx));
        R_JB(2, 0) = A.let(2 * (xz - wy)), R_JB(2, 1) = A.let(2 * (yz + wx)), R_JB(2, 2) = A.let(1 - 2 * (xx + yy));
        e_J = SV3{{q[q0], q[q0 + 1], q[q0 + 2]}};
        if (with_velocity) {
          const int u0 = b.u_joint;
          e_dot_B = SV3{{ctx.x.u[u0], ctx.x.u[u0 + 1], ctx.x.u[u0 + 2]}};
          w_rel_B = SV3{{ctx.x.u[u0 + 3], ctx.x.u[u0 + 4], ctx.x.u[u0 + 5]}};
        }
        break;
      }
    }
    s.R_PJ = R_PJ;
    s.R_JB = R_JB;
    const SM3 R_JP = R_PJ.transpose(), R_BJ = R_JB.transpose(), R_SP = s.R_PS.transpose();
    // a vector of the parent's (P components) in J components
    auto to_J = [&](const SV3& x) { return A.mul(R_JP, s.screw ? A.mul(R_SP, x) : x); };
    // O_J from O_P in J components: a model constant unless O_J is a node of a flexible parent
    const SV3 p_J = b.joint.node >= 0 || misaligned || moved ? to_J(p_PJ)
                                      : ctx.cvec(snapped(Vec3(b.joint.R_PJ.transpose() * b.joint.p_PJ)), n + "_p_J", "m",
                                                 "joint origin from the parent's origin, joint axes");
    s.p_BP_J = A.add(p_J, e_J);
    if (s.screw) {
      s.R_PB = A.mul(s.R_PS, A.mul(R_PJ, R_JB), ctx.name("R_PB", j));
      s.p_PO_P = A.add(p_PJ, A.mul(s.R_PS, A.mul(R_PJ, e_J)), ctx.name("p_PO_P", j));
    } else {
      s.R_PB = A.mul(R_PJ, R_JB, ctx.name("R_PB", j));
      s.p_PO_P = A.add(p_PJ, A.mul(R_PJ, e_J), ctx.name("p_PO_P", j));
    }
    // The transforms between B and P (spatial_transforms.cpp) turn by R_JB, then
    // by R_PJ. When R_PJ is dense and R_JB is not the identity, one turn by the
    // product R_PB is cheaper: then J stands for P (R_PJ = I, R_JB = R_PB).
    auto nonzeros = [](const SM3& R) {
      int k = 0;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) k += R(r, c).is_zero() ? 0 : 1;
      return k;
    };
    auto identity = [](const SM3& R) {
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          if (!(R(r, c) - (r == c ? 1 : 0)).is_zero()) return false;
      return true;
    };
    if (!s.screw && nonzeros(R_PJ) > 5 && !identity(R_JB)) {
      s.R_PJ = SM3::identity();
      s.R_JB = s.R_PB;
      s.p_BP_J = s.p_PO_P;
    }
    if (has_parent) {
      s.R_NB = A.mul(p->R_NB, s.R_PB, ctx.name("R_NB", j));
      s.r_NO_N = A.add(p->r_NO_N, A.mul(p->R_NB, s.p_PO_P), ctx.name("r_NO_N", j));
    } else {
      s.R_NB = s.R_PB;
      s.r_NO_N = s.p_PO_P;
    }
    // Node coupling: partials of [v; w] w.r.t. the parent's modal speeds.
    s.P_node.clear();
    for (int mode = 0; mode < static_cast<int>(H_cols.size()); ++mode) {
      const SV3 H_J = A.mul(R_JP, H_cols[mode]);
      const SV3 lin = A.mul(R_BJ, A.sub(A.mul(R_JP, Phi_cols[mode]), A.cross(e_J, H_J)));
      const SV3 ang = A.mul(R_BJ, H_J);
      s.P_node.push_back({lin[0], lin[1], lin[2], ang[0], ang[1], ang[2]});
    }
    if (!with_velocity) continue;
    // The parent's motion at O_J and the node's own, J components.
    const SV3 wP = to_J(w_P), alP = to_J(alR_P);
    const SV3 wJ = A.mul(R_JP, w_J), wJdot = A.mul(R_JP, w_J_dot_R);
    const SV3 vnode = A.mul(R_JP, v_node), anode = A.mul(R_JP, a_node_R);
    const SV3 w_in = A.add(wP, wJ);
    const SV3 vP0 = A.add(to_J(v_P), A.cross(wP, p_J));
    const SV3 aP0 = A.add(A.add(to_J(aR_P), A.cross(alP, p_J)), A.cross(wP, A.cross(wP, p_J)));
    // w_B = R_BJ (w_P + w_J) + w_rel; v_O_B = R_BJ (v_OJ + v_node + (w_P + w_J) x e) + e_dot
    const SV3 wt = A.mul(R_BJ, w_in);
    s.w_B = A.add(wt, w_rel_B, ctx.name("w_B", j));
    s.v_O_B = A.add(A.mul(R_BJ, A.add(A.add(vP0, vnode), A.cross(w_in, e_J))), e_dot_B, ctx.name("v_O_B", j));
    // alpha_R = R_BJ (alpha_P + w_P x w_J + w_J_dot) + (R_BJ (w_P + w_J)) x w_rel
    s.alpha_R_B = A.add(A.mul(R_BJ, A.add(A.add(alP, A.cross(wP, wJ)), wJdot)), A.cross(wt, w_rel_B),
                        ctx.name("alpha_R_B", j));
    // a_R = R_BJ [a_OJ + alpha_P x e + w_P x (w_P x e) + 2 w_P x (v_node + w_J x e) + w_J_dot x e
    //             + w_J x (w_J x e) + a_node] + (2 R_BJ (w_P + w_J) + w_rel) x e_dot
    SV3 a = A.add(aP0, A.cross(alP, e_J));
    a = A.add(a, A.cross(wP, A.cross(wP, e_J)));
    a = A.add(a, A.scale(2, A.cross(wP, A.add(vnode, A.cross(wJ, e_J)))));
    a = A.add(a, A.cross(wJdot, e_J));
    a = A.add(a, A.cross(wJ, A.cross(wJ, e_J)));
    a = A.add(a, anode);
    s.a_R_B = A.add(A.mul(R_BJ, a), A.cross(A.add(A.scale(2, wt), w_rel_B), e_dot_B), ctx.name("a_R_B", j));
    if (!s.S_joint.empty()) {
      s.alpha_R_B = A.add(s.alpha_R_B, bias_w_B, ctx.name("alpha_R_B", j));
      s.a_R_B = A.add(s.a_R_B, bias_v_B, ctx.name("a_R_B", j));
    }
    if (b.joint.prescribed()) {  // the known acceleration along the joint's column (axis in B = axis in J)
      SV3& target = b.joint.type == JointType::revolute ? s.alpha_R_B : s.a_R_B;
      target = A.add(target, A.scale(f_ddot, axis), ctx.name(b.joint.type == JointType::revolute ? "alpha_R_B" : "a_R_B", j));
    }
  }
}

}  // namespace kanegen::codegen
