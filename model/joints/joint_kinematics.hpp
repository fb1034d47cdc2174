// One joint's kinematics, written once over the algebra: S is double for the
// generic engine and GiNaC::ex for the generator (a `let` callback names the
// generator's intermediate results; the numeric side passes the identity).
// For a list of primitives (joint_primitive.hpp) it returns, with q and u the
// joint's own coordinates and speeds:
//   R_JB      orientation of B in J (x_J = R_JB x_B);
//   e_J       O_B relative to O_J, J components;
//   Sw, Sv    the motion subspace, B components, one column per speed:
//             w_rel_B = Sw u (B relative to J), e_dot_B = Sv u (rate of e seen in J);
//   bias_w_B, bias_v_B  its rate S_dot u (component-wise derivative in B), so that the
//             accelerations relative to J are  alpha_rel = Sw u_dot + bias_w  and
//             a_rel = Sv u_dot + bias_v + w_rel x e_dot (B components).
// The recursion runs through the intermediate frames k of the primitives in
// their own components (Craig's outward recursion for a massless chain):
//   rotation by Rk = Rot(a, th):  columns and rates turn by Rk^T,
//     alpha_b += (Rk^T w) x a th_dot,  w = Rk^T w + a th_dot;
//   translation d = a s:  Sv_c += Sw_c x d,
//     a_b += alpha_b x d + w x (w x d) + 2 w x a s_dot,  v += w x d + a s_dot;
//   sphere:  as a rotation with Rk = R(quat / |quat|) and w += u_{0..2};
//   free (first primitive only): e = xyz, Rk = R(quat), Sv = Sw = I, a_b = w x v.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "model/joints/joint_primitive.hpp"

namespace kanegen::joints {

template <class S>
using Vec = std::array<S, 3>;
template <class S>
using Mat = std::array<std::array<S, 3>, 3>;  ///< row-major

template <class S>
struct JointMotion {
  Mat<S> R_JB;
  Vec<S> e_J;
  std::array<Vec<S>, kMaxJointSpeeds> Sw, Sv;  ///< columns 0..nu-1, B components
  Vec<S> w_rel_B, e_dot_B;     ///< S u (zero when formed without velocities)
  Vec<S> bias_w_B, bias_v_B;   ///< S_dot u
};

namespace detail {

template <class S>
Vec<S> zero() { return {S(0), S(0), S(0)}; }
template <class S>
Mat<S> identity() {
  Mat<S> m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m[r][c] = S(r == c ? 1 : 0);
  return m;
}
template <class S>
Mat<S> mul(const Mat<S>& a, const Mat<S>& b) {
  Mat<S> m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m[r][c] = a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c];
  return m;
}
template <class S>
Vec<S> mul(const Mat<S>& a, const Vec<S>& v) {
  return {a[0][0] * v[0] + a[0][1] * v[1] + a[0][2] * v[2], a[1][0] * v[0] + a[1][1] * v[1] + a[1][2] * v[2],
          a[2][0] * v[0] + a[2][1] * v[1] + a[2][2] * v[2]};
}
template <class S>
Vec<S> mul_t(const Mat<S>& a, const Vec<S>& v) {  ///< a^T v
  return {a[0][0] * v[0] + a[1][0] * v[1] + a[2][0] * v[2], a[0][1] * v[0] + a[1][1] * v[1] + a[2][1] * v[2],
          a[0][2] * v[0] + a[1][2] * v[1] + a[2][2] * v[2]};
}
template <class S>
Vec<S> cross(const Vec<S>& a, const Vec<S>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
template <class S>
Vec<S> add(const Vec<S>& a, const Vec<S>& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
template <class S>
Vec<S> sub(const Vec<S>& a, const Vec<S>& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
template <class S>
Vec<S> scale(const S& s, const Vec<S>& a) { return {s * a[0], s * a[1], s * a[2]}; }

/// Rot(a, th) = I + sin th a^x + (1 - cos th) a^x a^x, unit a.
template <class S>
Mat<S> axis_rotation(const Vec<S>& a, const S& c, const S& s) {
  const Mat<S> A = {{{S(0), -a[2], a[1]}, {a[2], S(0), -a[0]}, {-a[1], a[0], S(0)}}};
  const Mat<S> AA = mul(A, A);
  Mat<S> R;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) R[r][k] = S(r == k ? 1 : 0) + s * A[r][k] + (S(1) - c) * AA[r][k];
  return R;
}

/// R(quat), quat = [w x y z] unit (dynamics.md).
template <class S>
Mat<S> quaternion_rotation(const S& w, const S& x, const S& y, const S& z) {
  return {{{S(1) - S(2) * (y * y + z * z), S(2) * (x * y - w * z), S(2) * (x * z + w * y)},
           {S(2) * (x * y + w * z), S(1) - S(2) * (x * x + z * z), S(2) * (y * z - w * x)},
           {S(2) * (x * z - w * y), S(2) * (y * z + w * x), S(1) - S(2) * (x * x + y * y)}}};
}

}  // namespace detail

/// sin and cos of a rotation's coordinate: the number type's own.
struct OwnSinCos {
  template <class S>
  std::pair<S, S> operator()(const S& x) const {
    using std::cos;
    using std::sin;
    return {sin(x), cos(x)};
  }
};

/// The joint's kinematics (see the header comment). `axes[i]` is primitive i's
/// axis converted to S; q and u point at the joint's own coordinates and
/// speeds (u may be null when with_velocity is false); `let` names an
/// intermediate value (identity for numbers); `sin_cos(x)` gives {sin x, cos x}
/// (the generator's: from its batch of joint angles, Program::sincos).
template <class S, class Let, class SinCos = OwnSinCos>
JointMotion<S> joint_motion(const std::vector<JointPrimitive>& prims, const std::vector<Vec<S>>& axes, int nu,
                            const S* q, const S* u, bool with_velocity, Let&& let, SinCos sin_cos = {}) {
  using namespace detail;
  using std::cos;
  using std::sin;
  using std::sqrt;
  auto let_v = [&](const Vec<S>& v) { return Vec<S>{let(v[0]), let(v[1]), let(v[2])}; };
  auto let_m = [&](const Mat<S>& m) {
    Mat<S> r;
    for (int i = 0; i < 3; ++i) r[i] = let_v(m[i]);
    return r;
  };
  JointMotion<S> jm;
  jm.R_JB = identity<S>();
  jm.e_J = zero<S>();
  jm.Sw.fill(zero<S>());
  jm.Sv.fill(zero<S>());
  Vec<S> w = zero<S>(), v = zero<S>(), alb = zero<S>(), ab = zero<S>();
  auto turn = [&](const Mat<S>& Rk) {  // into the new frame: columns, rates and biases by Rk^T
    jm.R_JB = let_m(mul(jm.R_JB, Rk));
    for (int c = 0; c < nu; ++c) jm.Sw[c] = let_v(mul_t(Rk, jm.Sw[c])), jm.Sv[c] = let_v(mul_t(Rk, jm.Sv[c]));
    if (!with_velocity) return;
    w = let_v(mul_t(Rk, w)), v = let_v(mul_t(Rk, v));
    alb = let_v(mul_t(Rk, alb)), ab = let_v(mul_t(Rk, ab));
  };
  for (std::size_t i = 0; i < prims.size(); ++i) {
    const JointPrimitive& p = prims[i];
    const Vec<S>& a = axes[i];
    switch (p.kind) {
      case JointPrimitive::Kind::rotation: {
        const auto [s_q, c_q] = sin_cos(q[p.q]);
        const S c = let(c_q), s = let(s_q);
        turn(let_m(axis_rotation(a, c, s)));
        jm.Sw[p.u] = add(jm.Sw[p.u], a);
        if (with_velocity) {
          const Vec<S> wa = scale(u[p.u], a);
          alb = let_v(add(alb, cross(w, wa)));
          w = let_v(add(w, wa));
        }
        break;
      }
      case JointPrimitive::Kind::translation: {
        const Vec<S> d = scale(q[p.q], a);
        jm.e_J = let_v(add(jm.e_J, mul(jm.R_JB, d)));
        for (int c = 0; c < nu; ++c) jm.Sv[c] = let_v(add(jm.Sv[c], cross(jm.Sw[c], d)));
        jm.Sv[p.u] = add(jm.Sv[p.u], a);
        if (with_velocity) {
          const Vec<S> va = scale(u[p.u], a);
          ab = let_v(add(add(ab, cross(alb, d)), add(cross(w, cross(w, d)), scale(S(2), cross(w, va)))));
          v = let_v(add(v, add(cross(w, d), va)));
        }
        break;
      }
      case JointPrimitive::Kind::sphere:
      case JointPrimitive::Kind::free: {
        const bool free = p.kind == JointPrimitive::Kind::free;
        const int q4 = p.q + (free ? 3 : 0), uw = p.u + (free ? 3 : 0);
        if (free) jm.e_J = let_v(add(jm.e_J, mul(jm.R_JB, Vec<S>{q[p.q], q[p.q + 1], q[p.q + 2]})));
        const S inv = let(S(1) / sqrt(q[q4] * q[q4] + q[q4 + 1] * q[q4 + 1] + q[q4 + 2] * q[q4 + 2] + q[q4 + 3] * q[q4 + 3]));
        turn(let_m(quaternion_rotation(let(q[q4] * inv), let(q[q4 + 1] * inv), let(q[q4 + 2] * inv), let(q[q4 + 3] * inv))));
        for (int c = 0; c < 3; ++c) {
          jm.Sw[uw + c][c] = jm.Sw[uw + c][c] + S(1);
          if (free) jm.Sv[p.u + c][c] = jm.Sv[p.u + c][c] + S(1);
        }
        if (with_velocity) {
          const Vec<S> ws = {u[uw], u[uw + 1], u[uw + 2]};
          alb = let_v(add(alb, cross(w, ws)));
          w = let_v(add(w, ws));
          if (free) {
            const Vec<S> vs = {u[p.u], u[p.u + 1], u[p.u + 2]};
            ab = let_v(add(ab, cross(w, vs)));  // d/dt in J of R v = R (v_dot + w x v); the free joint comes first
            v = let_v(add(v, vs));
          }
        }
        break;
      }
    }
  }
  jm.w_rel_B = w;
  jm.e_dot_B = v;
  jm.bias_w_B = alb;
  jm.bias_v_B = with_velocity ? let_v(sub(ab, cross(w, v))) : zero<S>();
  return jm;
}

/// q_dot = W(q) u of the joint (dynamics.md joint table): rates for rotations
/// and translations, 1/2 quat (x) [0, w] for a quaternion (as given: its norm
/// is preserved by the flow), R(quat) v for a free joint's position.
template <class S>
void joint_qdot(const std::vector<JointPrimitive>& prims, const S* q, const S* u, S* qdot) {
  using std::sqrt;
  for (const JointPrimitive& p : prims) {
    switch (p.kind) {
      case JointPrimitive::Kind::rotation:
      case JointPrimitive::Kind::translation: qdot[p.q] = u[p.u]; break;
      case JointPrimitive::Kind::sphere:
      case JointPrimitive::Kind::free: {
        const bool free = p.kind == JointPrimitive::Kind::free;
        const int q4 = p.q + (free ? 3 : 0), uw = p.u + (free ? 3 : 0);
        const S w = q[q4], x = q[q4 + 1], y = q[q4 + 2], z = q[q4 + 3];
        const S ox = u[uw], oy = u[uw + 1], oz = u[uw + 2];
        qdot[q4] = (-x * ox - y * oy - z * oz) / S(2);
        qdot[q4 + 1] = (w * ox + y * oz - z * oy) / S(2);
        qdot[q4 + 2] = (w * oy - x * oz + z * ox) / S(2);
        qdot[q4 + 3] = (w * oz + x * oy - y * ox) / S(2);
        if (free) {
          const S inv = S(1) / sqrt(w * w + x * x + y * y + z * z);
          const auto R = detail::quaternion_rotation(w * inv, x * inv, y * inv, z * inv);
          const Vec<S> xyz = detail::mul(R, Vec<S>{u[p.u], u[p.u + 1], u[p.u + 2]});
          for (int k = 0; k < 3; ++k) qdot[p.q + k] = xyz[k];
        }
        break;
      }
    }
  }
}

}  // namespace kanegen::joints
