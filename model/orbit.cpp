#include "model/orbit.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace kanegen {

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

/// R3(raan) R1(i) R3(argp): perifocal (x to periapsis, z along h) to N.
Mat3 perifocal_to_N(const OrbitElements& el) {
  return (Eigen::AngleAxisd(el.raan, Vec3::UnitZ()) * Eigen::AngleAxisd(el.i, Vec3::UnitX()) *
          Eigen::AngleAxisd(el.argp, Vec3::UnitZ()))
      .toRotationMatrix();
}

void check_bound(double mu, double a, double e) {
  if (!(mu > 0) || !std::isfinite(mu)) throw std::invalid_argument("mu " + std::to_string(mu) + "; expected > 0");
  if (!(a > 0) || !std::isfinite(a)) throw std::invalid_argument("a " + std::to_string(a) + "; expected > 0");
  if (!(e >= 0 && e < 1)) throw std::invalid_argument("e " + std::to_string(e) + "; expected 0 <= e < 1");
}

/// The orbit frame's rules (templates/orbit_frame.inc) over double; the
/// quaternion of a rotation matrix as the attitude output's (qw >= 0).
namespace rules {
inline void attitude_quaternion(double R00, double R01, double R02, double R10, double R11, double R12, double R20,
                                double R21, double R22, double* q) {
  Mat3 R;
  R << R00, R01, R02, R10, R11, R12, R20, R21, R22;
  Eigen::Quaterniond Q(R);
  Q.normalize();
  const double sign = Q.w() < 0 ? -1.0 : 1.0;
  q[0] = sign * Q.w(), q[1] = sign * Q.x(), q[2] = sign * Q.y(), q[3] = sign * Q.z();
}
#include "templates/orbit_frame.inc"
}  // namespace rules

using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

}  // namespace

double orbital_period(double mu, double a) { return 2.0 * M_PI * std::sqrt(a * a * a / mu); }

OrbitState state_from_elements(double mu, const OrbitElements& el) {
  check_bound(mu, el.a, el.e);
  const double p = el.a * (1.0 - el.e * el.e);
  const double r = p / (1.0 + el.e * std::cos(el.nu));
  const double k = std::sqrt(mu / p);
  const Vec3 r_P(r * std::cos(el.nu), r * std::sin(el.nu), 0.0);
  const Vec3 v_P(-k * std::sin(el.nu), k * (el.e + std::cos(el.nu)), 0.0);
  const Mat3 R = perifocal_to_N(el);
  return {R * r_P, R * v_P};
}

OrbitElements elements_from_state(double mu, const OrbitState& s) {
  const Vec3& r = s.r_N;
  const Vec3& v = s.v_N;
  if (!r.allFinite() || !v.allFinite() || r.norm() == 0) throw std::invalid_argument("position or velocity not finite");
  if (!(0.5 * v.squaredNorm() - mu / r.norm() < 0)) throw std::invalid_argument("not a bound orbit (specific energy >= 0)");
  const Eigen::Matrix<double, 6, 1> y = osculating_elements(mu, s);
  return {y(0), y(1), y(2), y(3), y(4), y(5)};
}

Eigen::Matrix<double, 6, 1> osculating_elements(double mu, const OrbitState& s) {
  Eigen::Matrix<double, 6, 1> y;
  rules::orbit_elements_output(mu, s.r_N.data(), s.v_N.data(), y.data());
  return y;
}

Eigen::Matrix<double, 7, 1> attitude_lvlh(const OrbitState& s, const Mat3& R_NX) {
  const RowMat3 R = R_NX;
  Eigen::Matrix<double, 7, 1> y;
  rules::attitude_lvlh_output(s.r_N.data(), s.v_N.data(), R.data(), y.data());
  return y;
}

Vec3 angular_velocity_lvlh(const OrbitState& s, const Mat3& R_NX, const Vec3& w_X) {
  const RowMat3 R = R_NX;
  Vec3 y;
  rules::angular_velocity_lvlh_output(s.r_N.data(), s.v_N.data(), R.data(), w_X.data(), y.data());
  return y;
}

double eccentric_anomaly(double M, double e) {
  // Newton from E = M + e sin M (e < 1: converges monotonically after the first step)
  double E = M + e * std::sin(M);
  for (int k = 0; k < 50; ++k) {
    const double dE = (E - e * std::sin(E) - M) / (1.0 - e * std::cos(E));
    E -= dE;
    if (std::abs(dE) <= 4e-16 * std::max(1.0, std::abs(E))) break;
  }
  return E;
}

double true_anomaly_at(double mu, const OrbitElements& el, double t) {
  check_bound(mu, el.a, el.e);
  const double e = el.e, n = std::sqrt(mu / (el.a * el.a * el.a));
  const double E0 = 2.0 * std::atan2(std::sqrt(1.0 - e) * std::sin(el.nu / 2), std::sqrt(1.0 + e) * std::cos(el.nu / 2));
  const double M = E0 - e * std::sin(E0) + n * t;
  const double E = eccentric_anomaly(M, e);
  return 2.0 * std::atan2(std::sqrt(1.0 + e) * std::sin(E / 2), std::sqrt(1.0 - e) * std::cos(E / 2));
}

Eigen::Matrix3d lvlh_frame(const OrbitState& s) {
  RowMat3 R;
  rules::lvlh_axes(s.r_N.data(), s.v_N.data(), R.data());
  return R;
}

Eigen::Vector3d lvlh_rate_N(const OrbitState& s) {
  Vec3 w;
  rules::lvlh_rate(s.r_N.data(), s.v_N.data(), w.data());
  return w;
}

}  // namespace kanegen
