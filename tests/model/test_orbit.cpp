// Two-body orbits (model/orbit.hpp) against closed forms and an independent
// numerical integration of r'' = -mu r / |r|^3.
#include <catch2/catch.hpp>

#include <boost/numeric/odeint.hpp>
#include <random>

#include "model/orbit.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;
using Vec3 = Eigen::Vector3d;

namespace {
using kanegen::test::kMu;
double angle_diff(double a, double b) { return std::abs(std::remainder(a - b, 2.0 * M_PI)); }
}  // namespace

TEST_CASE("orbit: elements to state and back, vis-viva, angular momentum", "[orbit]") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int k = 0; k < 200; ++k) {
    OrbitElements el{6.6e6 + 3e7 * U(rng), 0.9 * U(rng), 0.05 + 3.0 * U(rng), 2 * M_PI * U(rng), 2 * M_PI * U(rng),
                     2 * M_PI * U(rng) - M_PI};
    const OrbitState s = state_from_elements(kMu, el);
    const double r = s.r_N.norm();
    CHECK(std::abs(s.v_N.squaredNorm() - kMu * (2 / r - 1 / el.a)) <= 1e-13 * s.v_N.squaredNorm());
    CHECK(std::abs(s.r_N.cross(s.v_N).norm() - std::sqrt(kMu * el.a * (1 - el.e * el.e))) <=
          1e-13 * s.r_N.cross(s.v_N).norm());
    const OrbitElements back = elements_from_state(kMu, s);
    INFO("orbit " << k << ": a " << el.a << " e " << el.e << " i " << el.i);
    CHECK(std::abs(back.a - el.a) <= 1e-11 * el.a);
    CHECK(std::abs(back.e - el.e) <= 1e-11);
    CHECK(angle_diff(back.i, el.i) <= 1e-11);
    CHECK(angle_diff(back.raan, el.raan) <= 1e-10);
    if (el.e > 1e-6) {
      CHECK(angle_diff(back.argp, el.argp) <= 1e-8);
      CHECK(angle_diff(back.nu, el.nu) <= 1e-8);
    }
  }
  CHECK_THROWS(state_from_elements(kMu, OrbitElements{7e6, 1.0, 0, 0, 0, 0}));
  CHECK_THROWS(state_from_elements(kMu, OrbitElements{-7e6, 0.1, 0, 0, 0, 0}));
  CHECK_THROWS(state_from_elements(-kMu, OrbitElements{7e6, 0.1, 0, 0, 0, 0}));
}

TEST_CASE("orbit: Kepler's equation, and the propagated orbit against a numerical integration", "[orbit]") {
  for (double e : {0.0, 0.1, 0.5, 0.9, 0.99})
    for (double M = -3.0; M <= 3.0; M += 0.25) {
      const double E = eccentric_anomaly(M, e);
      CHECK(std::abs(E - e * std::sin(E) - M) <= 2e-15 * std::max(1.0, std::abs(M)));
    }
  // e = 0.1 over 3 periods: the two-body ODE integrated at tight tolerances (rkf78) against Kepler's equation
  const OrbitElements el{7.5e6, 0.1, 0.6, 0.3, 1.1, 0.2};
  const OrbitState s0 = state_from_elements(kMu, el);
  using X = std::array<double, 6>;
  X x{s0.r_N.x(), s0.r_N.y(), s0.r_N.z(), s0.v_N.x(), s0.v_N.y(), s0.v_N.z()};
  auto rhs = [](const X& y, X& dy, double) {
    const Vec3 r(y[0], y[1], y[2]);
    const Vec3 a = -kMu * r / std::pow(r.norm(), 3);
    dy = {y[3], y[4], y[5], a.x(), a.y(), a.z()};
  };
  namespace ode = boost::numeric::odeint;
  const double T = orbital_period(kMu, el.a);
  double worst = 0.0;
  double t = 0.0;
  for (int k = 1; k <= 30; ++k) {
    const double t1 = k * T / 10;
    ode::integrate_adaptive(ode::make_controlled(1e-14, 1e-14, ode::runge_kutta_fehlberg78<X>()), rhs, x, t, t1, 1.0);
    t = t1;
    OrbitElements now = el;
    now.nu = true_anomaly_at(kMu, el, t1);
    const OrbitState s = state_from_elements(kMu, now);
    worst = std::max(worst, (s.r_N - Vec3(x[0], x[1], x[2])).norm() / s.r_N.norm());
  }
  INFO("Kepler against the integrated two-body problem over 3 orbits: " << worst);
  CHECK(worst <= 1e-9);
  // one period brings the anomaly back
  CHECK(angle_diff(true_anomaly_at(kMu, el, T), el.nu) <= 1e-12);
}

TEST_CASE("orbit: the LVLH frame (x along track, y against the orbit normal, z to nadir) and its rate", "[orbit]") {
  const OrbitState c = state_from_elements(kMu, OrbitElements{7e6, 0.0, 0.9, 0.4, 0.0, 1.3});
  const Eigen::Matrix3d R = lvlh_frame(c);
  CHECK((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() <= 1e-15);
  CHECK(std::abs(R.determinant() - 1.0) <= 1e-15);
  CHECK((R.col(0) - c.v_N.normalized()).norm() <= 1e-14);   // circular: along track is the velocity
  CHECK((R.col(2) + c.r_N.normalized()).norm() <= 1e-15);   // nadir
  const double n = std::sqrt(kMu / std::pow(7e6, 3));
  CHECK(std::abs(lvlh_rate_N(c).norm() - n) <= 1e-14 * n);  // the mean motion
  CHECK(lvlh_rate_N(c).dot(R.col(1)) < 0);                   // the frame turns about -y
  const OrbitState e = state_from_elements(kMu, OrbitElements{8e6, 0.3, 0.2, 0.0, 0.5, 2.0});
  const Eigen::Matrix3d Re = lvlh_frame(e);
  CHECK(Re.col(0).dot(e.v_N) > 0);
  CHECK(std::abs(Re.col(2).dot(e.v_N)) > 0);  // elliptic: the velocity has a radial part
}
