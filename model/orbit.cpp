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
  const Vec3 h = r.cross(v);
  const double rn = r.norm(), energy = 0.5 * v.squaredNorm() - mu / rn;
  if (!(energy < 0)) throw std::invalid_argument("not a bound orbit (specific energy >= 0)");
  const Vec3 e_vec = v.cross(h) / mu - r / rn;
  OrbitElements el;
  el.a = -mu / (2.0 * energy);
  el.e = e_vec.norm();
  el.i = std::atan2(std::hypot(h.x(), h.y()), h.z());
  const Vec3 n = Vec3::UnitZ().cross(h);  // towards the ascending node
  const bool equatorial = n.norm() <= 1e-15 * h.norm(), circular = el.e <= 1e-15;
  el.raan = equatorial ? 0.0 : std::atan2(n.y(), n.x());
  const Vec3 node = equatorial ? Vec3::UnitX() : Vec3(n / n.norm());
  const Vec3 across = h.normalized().cross(node);  // in the plane, 90 deg ahead of the node
  auto angle_in_plane = [&](const Vec3& x) { return std::atan2(x.dot(across), x.dot(node)); };
  el.argp = circular ? 0.0 : angle_in_plane(e_vec);
  el.nu = angle_in_plane(r) - el.argp;
  el.nu = std::remainder(el.nu, 2.0 * M_PI);
  if (el.argp < 0) el.argp += 2.0 * M_PI;
  if (el.raan < 0) el.raan += 2.0 * M_PI;
  return el;
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
  const Vec3 z = -s.r_N.normalized();
  const Vec3 y = -s.r_N.cross(s.v_N).normalized();
  Mat3 R;
  R.col(0) = y.cross(z);
  R.col(1) = y;
  R.col(2) = z;
  return R;
}

Eigen::Vector3d lvlh_rate_N(const OrbitState& s) { return s.r_N.cross(s.v_N) / s.r_N.squaredNorm(); }

}  // namespace kanegen
