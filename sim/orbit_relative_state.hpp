// The state relative to the orbit frame (docs/gnc.md, "Linear models in
// orbit"): the chart `kanegen linearize --frame lvlh` takes the linear model
// in. About a point x0 with the system's centre of mass on a circular orbit,
// the reference frame L_ref turns uniformly about the orbit normal h through
// the central body at n = |r x v| / |r|^2, from L at x0 (the orbit frame of
// the centre of mass, templates/orbit_frame.inc). The free root body's
// coordinates become
//   lvlh.x, lvlh.y, lvlh.z   its origin's displacement from its place at x0,
//                            carried round by L_ref: lvlh.x = r0 phi, the
//                            along-track arc (phi its angle about h relative
//                            to L_ref, r0 its distance from the h axis at
//                            x0), lvlh.y the offset along L's y (against h),
//                            lvlh.z the drop of its distance from the h axis
//                            (towards nadir);
//   lvlh.rx, .ry, .rz        its attitude relative to the local orbit frame
//                            L_loc (L_ref turned on by phi about h) against
//                            its attitude relative to L at x0, a small
//                            rotation in body axes (vee of E - E^T, over 2,
//                            E = R_LB(x0)^T R_LlocB);
// and its speeds lvlh.vx = r0 phi_dot, lvlh.vy, lvlh.vz (the rates of the
// first three) and lvlh.wx, .wy, .wz = w_B - R_BN (n + phi_dot) h (its
// angular velocity relative to L_loc, B components). Every other coordinate
// and speed is kept as it is (a ball joint's quaternion below the root as
// linearize's small rotation, 2 Xi(q0)^T q).
// A rotation of the whole system about h through the central body changes
// lvlh.x alone: in a field symmetric about h (a point mass; J2 with an
// equatorial orbit) lvlh.x is an ignorable coordinate, its A column zero.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "model/model.hpp"
#include "model/state_io.hpp"

namespace kanegen {

class OrbitRelativeState {
 public:
  /// About `state` of `model`: needs a central field and a free root body (throws InputError naming
  /// `option` otherwise).
  OrbitRelativeState(const Model& model, const State& state, const std::string& option = "--frame");

  /// The relative state z (nq - n_quaternions + nu entries, in the order of linearize's tangent states)
  /// of the full state q (nq), u (nu) at time t. S: double, Dual<double> or Dual<Dual<double>>.
  template <class S>
  void apply(const S* q, const S* u, const S& t, S* z) const;

  /// Names of z's entries: "q.<root>.lvlh.x" ..., "u.<root>.lvlh.vx" ..., the others' as linearize
  /// names them.
  const std::vector<std::string>& names() const { return names_; }
  int size() const { return static_cast<int>(names_.size()); }
  int root() const { return root_; }
  double orbit_rate() const { return n_; }       ///< n, rad/s
  double eccentricity() const { return e_; }     ///< the centre of mass's osculating e at x0
  /// The orbit-frame chart's x0 rule: the centre of mass, its velocity (N) at x0.
  const Eigen::Vector3d& com_position() const { return r_com_; }

 private:
  const Model& model_;
  int root_ = -1;
  double t0_ = 0, n_ = 0, e_ = 0, r0_ = 0, zh0_ = 0;
  Eigen::Vector3d r_com_;
  Eigen::Vector3d h_N_;            ///< orbit normal (unit), N components
  Eigen::Vector3d e0_N_;           ///< the unit vector from the h axis to the root's origin at x0
  Eigen::Matrix3d R_NL0_;          ///< L at x0
  Eigen::Matrix3d R_LB0_;          ///< the root's attitude relative to L at x0
  std::vector<Eigen::Vector4d> q0_of_slot_;  ///< each quaternion at x0 (its small rotation's base)
  std::vector<std::string> names_;
};

}  // namespace kanegen
