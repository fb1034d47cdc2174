// Motion subspaces S_j and the transforms between a body and its parent
// (Xe_j: the partial-velocity recursion P_child = Xe P_parent + S), the bias
// forces and the applied generalized forces that every symbolic pass shares.
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "codegen/kane_context.hpp"

namespace kanegen::codegen {

using namespace GiNaC;

std::vector<int> own_columns(const Model& model, int j) {
  const Body& b = model.bodies[j];
  std::vector<int> cols;
  for (int k = 0; k < joint_nu(b.joint) + b.n_modes(); ++k) cols.push_back(b.u_joint + k);
  return cols;
}

std::vector<std::vector<ex>> motion_subspace(KaneContext& ctx, int j) {
  const Body& b = ctx.model.bodies[j];
  const int m = b.n_modes();
  std::vector<std::vector<ex>> S;
  ctx.C.group = b.name;
  const SV3 axis = ctx.cvec(b.joint.axis_J, b.name + "_axis", "", "joint axis");
  switch (b.joint.prescribed() ? JointType::fixed : b.joint.type) {  // a prescribed joint has no column
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
      for (int c = 0; c < 6; ++c) {
        std::vector<ex> col(6 + m, ex(0));
        col[c] = 1;
        S.push_back(col);
      }
      break;
    default:  // the joint module's columns, formed by the outward pass (kinematics.cpp)
      for (const auto& c6 : ctx.body[j].S_joint) {
        std::vector<ex> col(6 + m, ex(0));
        for (int r = 0; r < 6; ++r) col[r] = c6[r];
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

std::vector<ex> transform_motion_from_parent(KaneContext& ctx, int j, const std::vector<ex>* dp) {
  const SymBodyWorkspace& s = ctx.body[j];
  std::vector<ex> dl(6 + ctx.model.bodies[j].n_modes(), ex(0));
  if (!dp) return dl;
  // [v; w] of the parent at O_B, in J then in B components: two sparse turns (three with a screw)
  const SM3 R_JP = s.R_PJ.transpose(), R_BJ = s.R_JB.transpose();
  SV3 w_P{{(*dp)[3], (*dp)[4], (*dp)[5]}}, v_P{{(*dp)[0], (*dp)[1], (*dp)[2]}};
  if (s.screw) w_P = ctx.A.mul(s.R_PS.transpose(), w_P), v_P = ctx.A.mul(s.R_PS.transpose(), v_P);
  const SV3 w_J = ctx.A.mul(R_JP, w_P);
  const SV3 v_J = ctx.A.add(ctx.A.mul(R_JP, v_P), ctx.A.cross(w_J, s.p_BP_J));
  const SV3 lin = ctx.A.mul(R_BJ, v_J), ang = ctx.A.mul(R_BJ, w_J);
  for (int a = 0; a < 3; ++a) dl[a] = lin[a], dl[3 + a] = ang[a];
  for (int i = 0; i < static_cast<int>(s.P_node.size()); ++i)
    for (int r = 0; r < 6; ++r) dl[r] = dl[r] + s.P_node[i][r] * (*dp)[6 + i];
  return dl;
}

std::vector<ex> transform_wrench_to_parent(KaneContext& ctx, int cidx, const std::vector<ex>& W6) {
  const SymBodyWorkspace& s = ctx.body[cidx];
  const int p = ctx.model.bodies[cidx].parent;
  const int m_P = ctx.model.bodies[p].n_modes();
  // [f; t about O_B] in J components, moved to the parent's origin, then in P components
  const SV3 f_J = ctx.A.mul(s.R_JB, SV3{{W6[0], W6[1], W6[2]}});
  const SV3 t_J = ctx.A.add(ctx.A.mul(s.R_JB, SV3{{W6[3], W6[4], W6[5]}}), ctx.A.cross(s.p_BP_J, f_J));
  SV3 fP = ctx.A.mul(s.R_PJ, f_J), tP = ctx.A.mul(s.R_PJ, t_J);
  if (s.screw) fP = ctx.A.mul(s.R_PS, fP), tP = ctx.A.mul(s.R_PS, tP);
  std::vector<ex> out(6 + m_P, ex(0));
  for (int a = 0; a < 3; ++a) out[a] = fP[a], out[3 + a] = tP[a];
  for (int i = 0; i < static_cast<int>(s.P_node.size()); ++i) {
    ex sum = 0;
    for (int r = 0; r < 6; ++r) sum += s.P_node[i][r] * W6[r];
    out[6 + i] = ctx.A.let(sum);
  }
  return out;
}

namespace {

/// R as a turn about coordinate axis k: row and column k those of the identity, the (i, j) block [c -s; s c]
/// ((i, j, k) cyclic), checked symbolically or, for model constants, by value (to 4 ulp). With it the terms
/// of the turned matrices' (i, j) blocks: ss = s^2, cs = c s, S2 = 2 c s, C2 = c^2 - s^2 (for a turn by model
/// constants, constants named after its cosine: every body's have one role, outlined_code.hpp).
struct AxisTurn {
  int i, j, k;
  ex c, s;
  ex ss, cs, S2, C2;
};

/// A constant turn's products of c and s as constants named after its cosine t.c (a constant symbol); its
/// cos of the double angle is given (as computed, or snapped to 0 at 45 degrees).
void name_turn_products(KaneContext& ctx, AxisTurn& t, double c, double s, double C2) {
  t.ss = ctx.C.companion(t.c, "ss", s * s, "a turn's sin^2");
  t.cs = ctx.C.companion(t.c, "cs", c * s, "a turn's cos sin");
  t.S2 = ctx.C.companion(t.c, "S2", 2 * c * s, "a turn's sin of the double angle");
  t.C2 = ctx.C.companion(t.c, "C2", C2, "a turn's cos of the double angle");
}

std::optional<AxisTurn> axis_turn(KaneContext& ctx, const SM3& R) {
  auto same = [&](const ex& a, const ex& b) {
    if ((a - b).is_zero()) return true;
    const auto va = ctx.C.numeric_value(a), vb = ctx.C.numeric_value(b);
    return va && vb && std::abs(*va - *vb) <= 4 * std::numeric_limits<double>::epsilon();
  };
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    bool ok = (R(k, k) - 1).is_zero();
    for (int t = 0; t < 3 && ok; ++t)
      if (t != k) ok = R(k, t).is_zero() && R(t, k).is_zero();
    if (!ok || R(i, i).is_zero() || R(j, i).is_zero()) continue;  // a quarter turn: the plain product is as cheap
    if (!same(R(j, j), R(i, i)) || !same(R(i, j), -R(j, i))) continue;
    AxisTurn t{i, j, k, R(i, i), R(j, i), 0, 0, 0, 0};
    const auto vc = ctx.C.numeric_value(t.c), vs = ctx.C.numeric_value(t.s);
    // the formulas take c^2 = 1 - s^2: a constant turn must be a rotation to rounding (the loader accepts a
    // user's matrix orthonormal to 1e-9, and that one is turned as given)
    if (vc && vs && std::abs(*vc * *vc + *vs * *vs - 1.0) > 4 * std::numeric_limits<double>::epsilon()) continue;
    if (vc && vs && is_a<symbol>(t.c)) {
      name_turn_products(ctx, t, *vc, *vs, *vc * *vc - *vs * *vs);
    } else {
      t.ss = ctx.A.let(t.s * t.s);
      t.cs = ctx.A.let(t.c * t.s);
      t.S2 = 2 * t.cs;
      t.C2 = ctx.A.let(1 - 2 * t.ss);
    }
    return t;
  }
  return std::nullopt;
}

/// The turn about coordinate axis k by the constants c = cos and s = sin of an angle, named after `base`
/// with `suffix` (every model constant has one role: outlined_code.hpp), or nullopt where c or s is 0 or 1
/// (no constant symbol to name the double angle's after).
std::optional<AxisTurn> constant_turn(KaneContext& ctx, int k, const ex& base, const std::string& suffix,
                                      double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  if (std::abs(c) < 1e-7 || std::abs(s) < 1e-7) return std::nullopt;  // cos or sin would round to 1
  const std::string what = "a turn of a constant rotation's z-x-z factors (spatial_transforms.cpp)";
  AxisTurn t{(k + 1) % 3, (k + 2) % 3, k, ctx.C.companion(base, suffix + "_c", c, what),
             ctx.C.companion(base, suffix + "_s", s, what), 0, 0, 0, 0};
  if (!is_a<symbol>(t.c) || !is_a<symbol>(t.s)) return std::nullopt;  // (an exact 0 or 1 is no constant)
  const double C2 = c * c - s * s;
  name_turn_products(ctx, t, c, s, std::abs(C2) < 4 * std::numeric_limits<double>::epsilon() ? 0.0 : C2);  // 45 deg
  return t;
}

/// A constant rotation with no coordinate axis of its own (a prismatic child's joint frame, which cannot
/// join a joint angle) as three turns about coordinate axes, R = Rz(a) Rx(b) Rz(c) (z-x-z angles), the
/// innermost first: an inertia turned by them costs 3 x 15 operations instead of 75.
std::optional<std::array<AxisTurn, 3>> euler_turns(KaneContext& ctx, const SM3& R) {
  Mat3 v;
  const ex* base = nullptr;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      const auto x = ctx.C.numeric_value(R(r, c));
      if (!x) return std::nullopt;
      v(r, c) = *x;
      if (!base && is_a<symbol>(R(r, c))) base = &R(r, c);
    }
  if (!base || !(v.transpose() * v).isIdentity(1e-12) || v.determinant() < 0) return std::nullopt;
  const double a = std::atan2(v(0, 2), -v(1, 2)), b = std::atan2(std::hypot(v(0, 2), v(1, 2)), v(2, 2)),
               c = std::atan2(v(2, 0), v(2, 1));
  const Mat3 back = rot_z(a) * rot_x(b) * rot_z(c);
  if (!back.isApprox(v, 1e-13)) return std::nullopt;
  const auto t1 = constant_turn(ctx, 2, *base, "zxz1", c), t2 = constant_turn(ctx, 0, *base, "zxz2", b),
             t3 = constant_turn(ctx, 2, *base, "zxz3", a);
  if (!t1 || !t2 || !t3) return std::nullopt;
  return std::array<AxisTurn, 3>{*t1, *t2, *t3};
}

/// R J R^T for a turn about a coordinate axis, J symmetric: with d = J_ii - J_jj and w = d ss + J_ij S2 the
/// (i, j) block is [J_ii - w, d cs + J_ij C2; ., J_jj + w] (9 operations instead of 21); column k by R.
SM3 turn_symmetric(KaneContext& ctx, const AxisTurn& t, const SM3& J) {
  const int i = t.i, j = t.j, k = t.k;
  SM3 out;
  const ex d = ctx.A.let(J(i, i) - J(j, j));
  const ex w = ctx.A.let(d * t.ss + J(i, j) * t.S2);
  out(i, i) = ctx.A.let(J(i, i) - w);
  out(j, j) = ctx.A.let(J(j, j) + w);
  out(i, j) = out(j, i) = ctx.A.let(d * t.cs + J(i, j) * t.C2);
  out(i, k) = out(k, i) = ctx.A.let(t.c * J(i, k) - t.s * J(j, k));
  out(j, k) = out(k, j) = ctx.A.let(t.s * J(i, k) + t.c * J(j, k));
  out(k, k) = J(k, k);
  return out;
}

/// R B R^T for a turn about a coordinate axis, B any 3 x 3: with d = B_ii - B_jj, e = B_ij + B_ji,
/// w = d ss + e cs and v = d cs - e ss the (i, j) block is [B_ii - w, B_ij + v; B_ji + v, B_jj + w] (12
/// operations instead of 24); row and column k by R.
SM3 turn_matrix(KaneContext& ctx, const AxisTurn& t, const SM3& B) {
  const int i = t.i, j = t.j, k = t.k;
  SM3 out;
  const ex d = ctx.A.let(B(i, i) - B(j, j)), e = ctx.A.let(B(i, j) + B(j, i));
  const ex w = ctx.A.let(d * t.ss + e * t.cs), v = ctx.A.let(d * t.cs - e * t.ss);
  out(i, i) = ctx.A.let(B(i, i) - w);
  out(j, j) = ctx.A.let(B(j, j) + w);
  out(i, j) = ctx.A.let(B(i, j) + v);
  out(j, i) = ctx.A.let(B(j, i) + v);
  out(i, k) = ctx.A.let(t.c * B(i, k) - t.s * B(j, k));
  out(j, k) = ctx.A.let(t.s * B(i, k) + t.c * B(j, k));
  out(k, i) = ctx.A.let(t.c * B(k, i) - t.s * B(k, j));
  out(k, j) = ctx.A.let(t.s * B(k, i) + t.c * B(k, j));
  out(k, k) = B(k, k);
  return out;
}

}  // namespace

SM3 rotate_symmetric(KaneContext& ctx, const SM3& R, const SM3& J) {
  if (const auto t = axis_turn(ctx, R)) return turn_symmetric(ctx, *t, J);
  if (const auto e = euler_turns(ctx, R)) {
    SM3 out = J;
    for (const AxisTurn& t : *e) out = turn_symmetric(ctx, t, out);
    return out;
  }
  SM3 RJ = ctx.A.mul(R, J), out;
  for (int a = 0; a < 3; ++a)
    for (int c = a; c < 3; ++c)
      out(a, c) = out(c, a) = ctx.A.let(RJ(a, 0) * R(c, 0) + RJ(a, 1) * R(c, 1) + RJ(a, 2) * R(c, 2));
  return out;
}

SM3 rotate_matrix(KaneContext& ctx, const SM3& R, const SM3& B) {
  if (const auto t = axis_turn(ctx, R)) return turn_matrix(ctx, *t, B);
  if (const auto e = euler_turns(ctx, R)) {
    SM3 out = B;
    for (const AxisTurn& t : *e) out = turn_matrix(ctx, t, out);
    return out;
  }
  return ctx.A.mul(ctx.A.mul(R, B), R.transpose());
}

SMat transform_inertia_to_parent(KaneContext& ctx, int j, const SMat& I) {
  const SymBodyWorkspace& s = ctx.body[j];
  // blocks of I in B components: [A B; B^T C] over [v; w]
  SM3 Am, Bm, Cm;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Am(r, c) = I(r, c), Bm(r, c) = I(r, 3 + c), Cm(r, c) = I(3 + r, 3 + c);
  // turn into J components
  Am = rotate_symmetric(ctx, s.R_JB, Am);
  Bm = rotate_matrix(ctx, s.R_JB, Bm);
  Cm = rotate_symmetric(ctx, s.R_JB, Cm);
  // move to the parent's origin: X = [I -P; 0 I], P = p^x; X^T I X =
  // [A, B - A P; B^T + P A, C + P B + (P B)^T - P A P]
  const SM3 P = Alg::skew(s.p_BP_J);
  const SM3 AP = ctx.A.mul(Am, P);
  SM3 B2, C2;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) B2(r, c) = ctx.A.let(Bm(r, c) - AP(r, c));
  // C + P B + (P B)^T - P A P = C + P B2 + (P B)^T (P B2 = P B - P A P): the upper triangle of P B2 and the
  // lower one of P B, 6 entries each, instead of all of P B and the upper triangle of P A P
  for (int r = 0; r < 3; ++r)
    for (int c = r; c < 3; ++c) {
      ex pb2 = 0, pb = 0;  // (P B2)(r, c), (P B)(c, r)
      for (int t = 0; t < 3; ++t) pb2 += P(r, t) * B2(t, c), pb += P(c, t) * Bm(t, r);
      C2(r, c) = C2(c, r) = ctx.A.let(Cm(r, c) + ctx.A.let(pb2) + ctx.A.let(pb));
    }
  // turn into P components
  Am = rotate_symmetric(ctx, s.R_PJ, Am);
  B2 = rotate_matrix(ctx, s.R_PJ, B2);
  C2 = rotate_symmetric(ctx, s.R_PJ, C2);
  if (s.screw) {
    Am = rotate_symmetric(ctx, s.R_PS, Am);
    B2 = rotate_matrix(ctx, s.R_PS, B2);
    C2 = rotate_symmetric(ctx, s.R_PS, C2);
  }
  SMat out(6, 6);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      out(r, c) = Am(r, c);
      out(r, 3 + c) = B2(r, c);
      out(3 + c, r) = B2(r, c);
      out(3 + r, 3 + c) = C2(r, c);
    }
  return out;
}

std::vector<std::vector<ex>> compute_bias_forces(KaneContext& ctx) {
  const int nb = static_cast<int>(ctx.model.bodies.size());
  std::vector<std::vector<ex>> y(nb);
  for (int j = 0; j < nb; ++j) {  // y_j = g_j - h_j - M_j z_R
    ctx.P.section(fmt::format("body {}: bias force", ctx.model.bodies[j].name));
    const SymBodyWorkspace& s = ctx.body[j];
    const int n = 6 + ctx.model.bodies[j].n_modes();
    y[j].resize(n);
    for (int r = 0; r < n; ++r) {
      ex sum = s.g_body[r] - s.h_body[r];
      for (int a = 0; a < 3; ++a) sum -= s.M_body(r, a) * s.a_R_B[a] + s.M_body(r, 3 + a) * s.alpha_R_B[a];
      y[j][r] = ctx.A.let(sum);
    }
    if (!ctx.model.inputs.empty()) {  // the named inputs' wrench on the body
      const std::vector<ex> W_in = input_wrench(ctx, j);
      for (std::size_t r = 0; r < W_in.size(); ++r)
        if (!W_in[r].is_zero()) y[j][r] = ctx.A.let(y[j][r] + W_in[r]);
    }
  }
  return y;
}

std::array<ex, 3> joint_spring(KaneContext& ctx, int j, int k) {
  const Body& b = ctx.model.bodies[j];
  ctx.C.group = b.name;
  const std::string sfx = joint_traits(b.joint.type).springs > 1 ? std::to_string(k + 1) : "";
  return {ctx.param(ParameterKind::stiffness, j, k)
              .value_or(ctx.c(b.joint.stiffness[k], b.name + "_k" + sfx, "N m/rad or N/m", "joint spring stiffness")),
          ctx.param(ParameterKind::damping, j, k)
              .value_or(ctx.c(b.joint.damping[k], b.name + "_c" + sfx, "N m s/rad or N s/m", "joint damping")),
          ctx.param(ParameterKind::rest, j, k)
              .value_or(ctx.c(b.joint.rest[k], b.name + "_rest" + sfx, "rad or m", "spring rest value"))};
}

std::array<ex, 2> modal_stiffness_damping(KaneContext& ctx, int j, int i) {
  const Body& b = ctx.model.bodies[j];
  const FlexibleData& f = *b.flex;
  ctx.C.group = b.name;
  const auto fr = ctx.param(ParameterKind::frequency, j, i), zeta = ctx.param(ParameterKind::damping_ratio, j, i);
  if (!fr && !zeta)
    return {ctx.c(f.K(i), fmt::format("{}_K{}", b.name, i + 1), "N m", "modal stiffness"),
            ctx.c(f.D(i), fmt::format("{}_D{}", b.name, i + 1), "N m s", "modal damping")};
  // K = w^2 Y, D = 2 zeta w Y with w = 2 pi f and the mode's modal mass Y
  const double w0 = 2.0 * M_PI * f.frequency_hz(i);
  const ex Y = ctx.c(f.K(i) / (w0 * w0), fmt::format("{}_Y{}", b.name, i + 1), "kg m^2", "modal mass");
  const ex w = ctx.A.let((fr ? *fr : ctx.c(f.frequency_hz(i), fmt::format("{}_f{}", b.name, i + 1), "Hz", "frequency")) *
                         ctx.c(2.0 * M_PI, "two_pi", "", "2 pi"));
  const ex z = zeta ? *zeta : ctx.c(f.damping_ratio(i), fmt::format("{}_zeta{}", b.name, i + 1), "", "damping ratio");
  return {ctx.A.let(w * w * Y), ctx.A.let(2 * z * w * Y)};
}

ex applied_force(KaneContext& ctx, int j, int own) {
  const Body& b = ctx.model.bodies[j];
  const int r = b.u_joint + own;
  ex f = ctx.x.tau[r];
  ctx.C.group = b.name;
  if (own < joint_nu(b.joint) && !ctx.model.inputs.empty()) f += joint_input(ctx, j, own);
  for (const SpringSlot& sl : spring_slots(b.joint)) {
    if (sl.u != own) continue;
    const auto [kk, cc, rest] = joint_spring(ctx, j, sl.value);
    f -= cc * ctx.x.u[b.u_joint + own];
    if (sl.q >= 0) f -= kk * (ctx.x.q[b.q_joint + sl.q] - rest);
  }
  if (own >= joint_nu(b.joint)) {
    const int i = own - joint_nu(b.joint);
    const auto [K, D] = modal_stiffness_damping(ctx, j, i);
    f -= K * ctx.x.q[b.q_eta + i] + D * ctx.x.u[b.u_eta + i];
  }
  return ctx.A.let(f);
}

}  // namespace kanegen::codegen
