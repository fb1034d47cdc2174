// Central gravity on every mass element (dynamics.md, "Forces"): the
// MacCullagh potential of each rigid part (mass m, com at r from the central
// body, inertia I about its com, N axes) and of each flexible node (its mass,
// displaced position and node-frame rotary inertia J'_k),
//   V = -mu m / |r| - mu / (2 |r|^3) (tr I - 3 r^T I r / |r|^2) + mu m J2 R^2 (3 r_z^2 - |r|^2) / (2 |r|^5),
// and its exact derivatives: the force -dV/dr at the element's point and the
// gravity-gradient torque 3 mu / |r|^5 (r x I r). In the body's velocity
// coordinates [v_O, w, eta_dot] an element at s (B) with force f and torque t
// (B components) adds [f; s x f + t; Phi~^T f + H^T t] to g_body, so the
// forcing and the reactions take central gravity as they take uniform gravity.
#pragma once

#include "dynamics/body_inertia.hpp"
#include "dynamics/workspace.hpp"
#include "model/model.hpp"

namespace kanegen {

template <class S>
struct ElementGravity {
  V3<S> force_N = V3<S>::Zero();
  V3<S> torque_N = V3<S>::Zero();  ///< about the element's point
  S V = S(0);
};

/// The field's potential, force and torque on one element at r (N) with mass m and inertia I_N about it.
template <class S>
ElementGravity<S> central_gravity_on(const CentralGravity& c, double m, const V3<S>& r, const M3<S>& I_N,
                                     bool has_inertia) {
  using std::sqrt;
  ElementGravity<S> e;
  const S mu = S(c.mu), r2 = r.squaredNorm(), rn = sqrt(r2), r3 = r2 * rn, r5 = r3 * r2;
  e.V = -mu * S(m) / rn;
  e.force_N = -(mu * S(m) / r3) * r;
  if (has_inertia) {
    const V3<S> Ir = I_N * r;
    const S tr = I_N.trace(), rIr = r.dot(Ir);
    e.V -= mu / (S(2) * r3) * (tr - S(3) * rIr / r2);
    e.force_N -= (S(1.5) * mu / r5) * (tr * r + S(2) * Ir - (S(5) * rIr / r2) * r);
    e.torque_N = (S(3) * mu / r5) * r.cross(Ir);
  }
  if (c.J2 != 0.0 && m != 0.0) {
    const S k = S(0.5 * c.mu * m * c.J2 * c.radius * c.radius), z2 = r(2) * r(2), r7 = r5 * r2;
    e.V += k * (S(3) * z2 - r2) / r5;
    const S a = S(3) * r2 - S(15) * z2;
    e.force_N -= (k / r7) * V3<S>(r(0) * a, r(1) * a, r(2) * (S(9) * r2 - S(15) * z2));
  }
  return e;
}

/// Calls f(m, s_B, Phi_t or nullptr, I_B about s, H or nullptr, has_inertia) for body b's rigid part and each
/// node (displaced, with its node-frame inertia), at the body's current eta (s.eta). Uses the node scratch.
template <class S, class F>
void for_each_mass_element(const Body& b, BodyWorkspace<S>& s, F&& f) {
  const RigidPart& rp = b.rigid;
  if (rp.mass != 0.0 || !rp.I_c_B.isZero(0.0))
    f(rp.mass, V3<S>(rp.com_B.cast<S>()), static_cast<const Eigen::Matrix<S, 3, Eigen::Dynamic>*>(nullptr),
      M3<S>(rp.I_c_B.cast<S>()), static_cast<const Eigen::Matrix<S, 3, Eigen::Dynamic>*>(nullptr),
      !rp.I_c_B.isZero(0.0));
  if (!b.flex) return;
  const FlexibleData& flex = *b.flex;
  for (int k = 0; k < static_cast<int>(flex.nodes.size()); ++k) {
    const ModalNode& node = flex.nodes[k];
    const V3<S> s_k = node_position<S>(flex, k, s.eta, s.node_Phi, s.node_m);
    const bool rotary = !node.J_B.isZero(0.0);
    V3<S> g;
    const M3<S> Jp = rotary ? node_rotary_inertia<S>(flex, k, s.eta, s.node_H, g) : M3<S>::Zero();
    f(node.mass, s_k, &s.node_Phi, Jp, rotary ? &s.node_H : nullptr, rotary);
  }
}

/// Replaces body terms' uniform gravity by the central field: g_body of every body (after compute_body_inertia).
template <class S>
void add_central_gravity(const Model& model, Workspace<S>& ws) {
  const CentralGravity& c = *model.central;
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const Body& b = model.bodies[i];
    BodyWorkspace<S>& s = ws.body[i];
    s.g_body.setZero();
    const int m = b.n_modes();
    for_each_mass_element(b, s, [&](double mass, const V3<S>& s_B, const auto* Phi_t, const M3<S>& I_B,
                                    const auto* H, bool has_inertia) {
      const V3<S> r = s.r_NO_N + s.R_NB * s_B;
      const M3<S> I_N = s.R_NB * I_B * s.R_NB.transpose();
      const ElementGravity<S> e = central_gravity_on<S>(c, mass, r, I_N, has_inertia);
      const V3<S> f_B = s.R_NB.transpose() * e.force_N, t_B = s.R_NB.transpose() * e.torque_N;
      s.g_body.template head<3>() += f_B;
      s.g_body.template segment<3>(3) += s_B.cross(f_B) + t_B;
      if (m && Phi_t) s.g_body.tail(m).noalias() += Phi_t->transpose() * f_B;
      if (m && H) s.g_body.tail(m).noalias() += H->transpose() * t_B;
    });
  }
}

/// The central field's potential energy of the whole system at the current kinematics.
template <class S>
S central_potential(const Model& model, Workspace<S>& ws) {
  S V = S(0);
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    BodyWorkspace<S>& s = ws.body[i];
    for_each_mass_element(model.bodies[i], s, [&](double mass, const V3<S>& s_B, const auto*, const M3<S>& I_B,
                                                   const auto*, bool has_inertia) {
      const V3<S> r = s.r_NO_N + s.R_NB * s_B;
      V += central_gravity_on<S>(*model.central, mass, r, M3<S>(s.R_NB * I_B * s.R_NB.transpose()), has_inertia).V;
    });
  }
  return V;
}

/// The field's acceleration at a point r (N): the point-mass attraction and J2.
template <class S>
V3<S> central_field_at(const CentralGravity& c, const V3<S>& r) {
  return central_gravity_on<S>(c, 1.0, r, M3<S>::Zero(), false).force_N;
}

}  // namespace kanegen
