// Rotation helpers, templated on the scalar type (double, autodiff, ...).
// Conventions of dynamics.md: quaternions [w, x, y, z] scalar first, Hamilton
// product, R(quat) takes child components to parent components; rpy [r, p, y]
// is Rz(y) Ry(p) Rx(r).
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <type_traits>

namespace kanegen {

template <class S>
using V3 = Eigen::Matrix<S, 3, 1>;
template <class S>
using M3 = Eigen::Matrix<S, 3, 3>;
template <class S>
using V4 = Eigen::Matrix<S, 4, 1>;

/// The matrix itself when its scalar is already S (no temporary), else a cast.
template <class S, class Derived>
decltype(auto) as_scalar(const Eigen::MatrixBase<Derived>& m) {
  if constexpr (std::is_same_v<S, typename Derived::Scalar>)
    return (m.derived());
  else
    return m.template cast<S>();
}

/// a^x: skew matrix with a^x b = a x b.
template <class S>
M3<S> skew(const V3<S>& a) {
  M3<S> m;
  m << S(0), -a(2), a(1), a(2), S(0), -a(0), -a(1), a(0), S(0);
  return m;
}

/// R(quat) for quat = [w, x, y, z] (assumed unit).
template <class S>
M3<S> quat_to_R(const V4<S>& q) {
  const S w = q(0), x = q(1), y = q(2), z = q(3);
  M3<S> R;
  R << S(1) - S(2) * (y * y + z * z), S(2) * (x * y - w * z), S(2) * (x * z + w * y),
      S(2) * (x * y + w * z), S(1) - S(2) * (x * x + z * z), S(2) * (y * z - w * x),
      S(2) * (x * z - w * y), S(2) * (y * z + w * x), S(1) - S(2) * (x * x + y * y);
  return R;
}

/// Rot(a, theta): rotation by theta about unit axis a (right-hand rule).
template <class S>
M3<S> axis_angle_R(const Eigen::Vector3d& a, const S& theta) {
  using std::cos;
  using std::sin;
  const S c = cos(theta), s = sin(theta);
  const M3<S> A = skew<S>(a.cast<S>());
  return M3<S>::Identity() + s * A + (S(1) - c) * (A * A);
}

/// Rodrigues-parameter rotation C(theta) = I + 2/(1+g.g) (g^x + g^x g^x),
/// g = theta/2 (exact, orthogonal, I + theta^x to first order).
template <class S>
M3<S> rodrigues_R(const V3<S>& theta) {
  const V3<S> g = theta / S(2);
  const M3<S> G = skew<S>(g);
  return M3<S>::Identity() + (S(2) / (S(1) + g.dot(g))) * (G + G * G);
}

/// Hamilton product p (x) q.
template <class S>
V4<S> quat_mul(const V4<S>& p, const V4<S>& q) {
  V4<S> r;
  r(0) = p(0) * q(0) - p(1) * q(1) - p(2) * q(2) - p(3) * q(3);
  r(1) = p(0) * q(1) + p(1) * q(0) + p(2) * q(3) - p(3) * q(2);
  r(2) = p(0) * q(2) - p(1) * q(3) + p(2) * q(0) + p(3) * q(1);
  r(3) = p(0) * q(3) + p(1) * q(2) - p(2) * q(1) + p(3) * q(0);
  return r;
}

inline Eigen::Matrix3d rpy_R(double r, double p, double y) {
  return (Eigen::AngleAxisd(y, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(p, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace kanegen
