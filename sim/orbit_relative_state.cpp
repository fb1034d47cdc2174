#include "sim/orbit_relative_state.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>

#include "dynamics/sensors.hpp"
#include "model/diagnostics.hpp"
#include "model/orbit.hpp"
#include "sim/dual_number.hpp"
#include "sim/linearize.hpp"

namespace kanegen {

namespace orbit_chart {  // named: the unity batch has other V3 and dot

template <class S>
using V3 = std::array<S, 3>;

template <class S>
S dot(const V3<S>& a, const Eigen::Vector3d& b) {
  return a[0] * b(0) + a[1] * b(1) + a[2] * b(2);
}
template <class S>
S dot(const V3<S>& a, const V3<S>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
template <class S>
V3<S> cross(const Eigen::Vector3d& a, const V3<S>& b) {
  return {a(1) * b[2] - a(2) * b[1], a(2) * b[0] - a(0) * b[2], a(0) * b[1] - a(1) * b[0]};
}
template <class S>
V3<S> cross(const V3<S>& a, const V3<S>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
/// M a for a constant matrix.
template <class S>
V3<S> times(const Eigen::Matrix3d& M, const V3<S>& a) {
  V3<S> r;
  for (int i = 0; i < 3; ++i) r[i] = M(i, 0) * a[0] + M(i, 1) * a[1] + M(i, 2) * a[2];
  return r;
}
/// The rotation by angle (cos c, sin s) about the unit axis h applied to a (Rodrigues).
template <class S>
V3<S> rotate(const Eigen::Vector3d& h, const S& c, const S& s, const V3<S>& a) {
  const V3<S> hxa = cross(h, a);
  const S ha = dot(a, h);
  V3<S> r;
  for (int i = 0; i < 3; ++i) r[i] = c * a[i] + s * hxa[i] + (1.0 - c) * ha * h(i);
  return r;
}

}  // namespace orbit_chart

OrbitRelativeState::OrbitRelativeState(const Model& model, const State& state, const std::string& option)
    : model_(model), t0_(state.t) {
  auto refuse = [&](const std::string& why) { throw InputError(Diagnostic{"(command line)", 0, option, why}); };
  if (!model.central) refuse("the orbit frame needs a central field (gravity: central:)");
  root_ = model.orbit_root;
  if (root_ < 0)
    for (std::size_t i = 0; i < model.bodies.size(); ++i)
      if (model.bodies[i].parent < 0 && model.bodies[i].joint.type == JointType::free) {
        root_ = static_cast<int>(i);
        break;
      }
  if (root_ < 0) refuse("the orbit frame needs a free root body (joint: {type: free} on ground)");
  const Body& b = model.bodies[root_];

  // the centre of mass at x0: L, n and h
  const OrbitState c = system_centre_of_mass(model, state.t, state.q, state.u);
  r_com_ = c.r_N;
  const Eigen::Vector3d h = c.r_N.cross(c.v_N);
  if (h.norm() <= 1e-12 * c.r_N.norm() * c.v_N.norm())
    refuse("the centre of mass has no orbit at this state (its velocity is along its position or zero)");
  h_N_ = h.normalized();
  n_ = h.norm() / c.r_N.squaredNorm();
  e_ = osculating_elements(model.central->mu, c)(1);
  R_NL0_ = lvlh_frame(c);

  // the root at x0
  const VecX& q = state.q;
  const Eigen::Vector4d qq = q.segment<4>(b.q_joint + 3).normalized();
  const Mat3 R_NB0 = b.joint.R_PJ * Eigen::Quaterniond(qq(0), qq(1), qq(2), qq(3)).toRotationMatrix();
  R_LB0_ = R_NL0_.transpose() * R_NB0;
  const Eigen::Vector3d P0 = b.joint.p_PJ + b.joint.R_PJ * q.segment<3>(b.q_joint);
  zh0_ = h_N_.dot(P0);
  const Eigen::Vector3d perp = P0 - zh0_ * h_N_;
  r0_ = perp.norm();
  if (r0_ <= 1e-9 * c.r_N.norm()) refuse("the root body's origin is on the orbit normal through the central body");
  e0_N_ = perp / r0_;

  // names, in linearize's tangent order
  for (const auto& slot : model.quaternions) q0_of_slot_.push_back(q.segment<4>(slot.q).normalized());
  for (int i = 0; i < model.nq;) {
    if (i == b.q_joint) {
      for (const char* a : {"x", "y", "z", "rx", "ry", "rz"}) names_.push_back("q." + b.name + ".lvlh." + a);
      i += 7;
      continue;
    }
    bool quaternion = false;
    for (const auto& slot : model.quaternions)
      if (slot.q == i) {
        for (const char* a : {".rx", ".ry", ".rz"}) names_.push_back("q." + model.bodies[slot.body].name + a);
        quaternion = true;
      }
    if (quaternion) {
      i += 4;
      continue;
    }
    names_.push_back("q." + model.q_names[i]);
    ++i;
  }
  for (int k = 0; k < model.nu;) {
    if (k == b.u_joint) {
      for (const char* a : {"vx", "vy", "vz", "wx", "wy", "wz"}) names_.push_back("u." + b.name + ".lvlh." + a);
      k += 6;
      continue;
    }
    names_.push_back("u." + model.u_names[k]);
    ++k;
  }
}

template <class S>
void OrbitRelativeState::apply(const S* q, const S* u, const S& t, S* z) const {
  using Vec = orbit_chart::V3<S>;
  const Body& b = model_.bodies[root_];
  const Eigen::Matrix3d& R_NJ = b.joint.R_PJ;
  const Eigen::Vector3d& h = h_N_;
  // the root: R_NB = R_NJ R(quat) (the unit quaternion's rotation), P = p_J + R_NJ [x y z], V = R_NB v
  const S* qb = q + b.q_joint;
  const S* ub = u + b.u_joint;
  const S w = qb[3], x = qb[4], y = qb[5], zq = qb[6];
  const S R_JB[3][3] = {{w * w + x * x - y * y - zq * zq, 2.0 * (x * y - w * zq), 2.0 * (x * zq + w * y)},
                        {2.0 * (x * y + w * zq), w * w - x * x + y * y - zq * zq, 2.0 * (y * zq - w * x)},
                        {2.0 * (x * zq - w * y), 2.0 * (y * zq + w * x), w * w - x * x - y * y + zq * zq}};
  Vec col[3];  // R_NB's columns
  for (int j = 0; j < 3; ++j) col[j] = orbit_chart::times(R_NJ, Vec{R_JB[0][j], R_JB[1][j], R_JB[2][j]});
  Vec P = orbit_chart::times(R_NJ, Vec{qb[0], qb[1], qb[2]});
  for (int i = 0; i < 3; ++i) P[i] = P[i] + b.joint.p_PJ(i);
  Vec V;
  for (int i = 0; i < 3; ++i) V[i] = col[0][i] * ub[0] + col[1][i] * ub[1] + col[2][i] * ub[2];

  // carried back by L_ref's turn alpha = n (t - t0): Pr = Rot(h, -alpha) P, and its rate in that frame
  using std::atan2, std::cos, std::sin, std::sqrt;
  const S alpha = n_ * (t - t0_);
  const S ca = cos(alpha), sa = sin(alpha);
  const Vec Pr = orbit_chart::rotate(h, ca, -sa, P);
  const Vec hxPr = orbit_chart::cross(h, Pr);
  Vec Vr = orbit_chart::rotate(h, ca, -sa, V);
  for (int i = 0; i < 3; ++i) Vr[i] = Vr[i] - n_ * hxPr[i];
  // cylinder coordinates about h
  const S zh = orbit_chart::dot(Pr, h), zh_dot = orbit_chart::dot(Vr, h);
  Vec perp, v_perp;
  for (int i = 0; i < 3; ++i) perp[i] = Pr[i] - zh * h(i), v_perp[i] = Vr[i] - zh_dot * h(i);
  const S rho2 = orbit_chart::dot(perp, perp);
  const S rho = sqrt(rho2);
  const Vec e0xp = orbit_chart::cross(e0_N_, perp);
  const S phi = atan2(orbit_chart::dot(e0xp, h), orbit_chart::dot(perp, e0_N_));
  const S rho_dot = orbit_chart::dot(perp, v_perp) / rho;
  const S phi_dot = orbit_chart::dot(orbit_chart::cross(perp, v_perp), h) / rho2;

  // the attitude relative to L_loc: E = R_LB0^T R_L0N Rot(h, -(alpha + phi)) R_NB
  const S beta = alpha + phi;
  const S cb = cos(beta), sb = sin(beta);
  const Eigen::Matrix3d R_B0N = (R_NL0_ * R_LB0_).transpose();
  S E[3][3];
  for (int j = 0; j < 3; ++j) {
    const Vec c = orbit_chart::times(R_B0N, orbit_chart::rotate(h, cb, -sb, col[j]));
    for (int i = 0; i < 3; ++i) E[i][j] = c[i];
  }
  // w_B - (n + phi_dot) R_BN h
  const S rate = n_ + phi_dot;
  Vec w_rel;
  for (int j = 0; j < 3; ++j) w_rel[j] = ub[3 + j] - rate * orbit_chart::dot(col[j], h);

  // z in linearize's tangent order
  int r = 0;
  for (int i = 0; i < model_.nq;) {
    if (i == b.q_joint) {
      z[r++] = r0_ * phi;
      z[r++] = -(zh - zh0_);
      z[r++] = r0_ - rho;
      z[r++] = 0.5 * (E[2][1] - E[1][2]);
      z[r++] = 0.5 * (E[0][2] - E[2][0]);
      z[r++] = 0.5 * (E[1][0] - E[0][1]);
      i += 7;
      continue;
    }
    bool quaternion = false;
    for (std::size_t k = 0; k < model_.quaternions.size(); ++k)
      if (model_.quaternions[k].q == i && model_.quaternions[k].body != root_) {
        const Eigen::Matrix<double, 3, 4> Xt = 2.0 * quaternion_xi(q0_of_slot_[k]).transpose();
        for (int a = 0; a < 3; ++a) z[r++] = Xt(a, 0) * q[i] + Xt(a, 1) * q[i + 1] + Xt(a, 2) * q[i + 2] + Xt(a, 3) * q[i + 3];
        quaternion = true;
      }
    if (quaternion) {
      i += 4;
      continue;
    }
    z[r++] = q[i++];
  }
  for (int k = 0; k < model_.nu;) {
    if (k == b.u_joint) {
      z[r++] = r0_ * phi_dot;
      z[r++] = -zh_dot;
      z[r++] = -rho_dot;
      for (int a = 0; a < 3; ++a) z[r++] = w_rel[a];
      k += 6;
      continue;
    }
    z[r++] = u[k++];
  }
}

template void OrbitRelativeState::apply<double>(const double*, const double*, const double&, double*) const;
template void OrbitRelativeState::apply<Dual<double>>(const Dual<double>*, const Dual<double>*, const Dual<double>&,
                                                      Dual<double>*) const;
template void OrbitRelativeState::apply<Dual<Dual<double>>>(const Dual<Dual<double>>*, const Dual<Dual<double>>*,
                                                            const Dual<Dual<double>>&, Dual<Dual<double>>*) const;

}  // namespace kanegen
