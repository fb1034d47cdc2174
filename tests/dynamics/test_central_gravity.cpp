// Central gravity (dynamics.md, "Forces"; model-format.md, "Gravity") in the
// generic engine: the gravity-gradient torque against 3 mu / r^3 (r^ x I r^),
// the force against the potential's derivative, a Kepler orbit, and E and H
// kept over orbits by a flexible spacecraft (H_z only, with J2).
#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <random>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/orbit.hpp"
#include "sim/simulate.hpp"
#include "sim/row_sink.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

using test::kMu;

std::string sat(const std::string& gravity, const std::string& extra_body = "", const std::string& initial = "") {
  return "name: orbiter\ngravity: " + gravity + R"(
bodies:
  - name: sat
    parent: ground
    joint: {type: free}
    mass: 500.0
    com: [0.0, 0.0, 0.0]
    inertia: [300.0, 420.0, 250.0, 12.0, -7.0, 5.0]
)" + extra_body + initial;
}

}  // namespace

TEST_CASE("central gravity: gravity-gradient torque and force against closed forms, at random attitudes", "[central]") {
  const Model model = load_model(test::write_temp("gg.yaml", sat("{central: {mu: 3.986004418e14}}")));
  GenericEngine engine(model);
  std::mt19937 rng(3);
  std::normal_distribution<double> N01;
  const Mat3 I_B = (Mat3() << 300, 12, -7, 12, 420, 5, -7, 5, 250).finished();
  for (int k = 0; k < 20; ++k) {
    const Vec3 r = 7.0e6 * Vec3(N01(rng), N01(rng), N01(rng)).normalized();
    const Eigen::Quaterniond Q = Eigen::Quaterniond(N01(rng), N01(rng), N01(rng), N01(rng)).normalized();
    VecX q = VecX::Zero(model.nq), u = VecX::Zero(model.nu), F;
    q.head<3>() = r;
    q.segment<4>(3) << Q.w(), Q.x(), Q.y(), Q.z();
    engine.forcing(0.0, q, u, VecX::Zero(model.nu), F);
    const Mat3 R = Q.toRotationMatrix();
    const Mat3 I_N = R * I_B * R.transpose();
    const Vec3 rh = r.normalized();
    const Vec3 torque_B = R.transpose() * (3 * kMu / std::pow(r.norm(), 3) * rh.cross(I_N * rh));
    INFO("state " << k);
    CHECK((F.segment<3>(3) - torque_B).norm() <= 1e-12 * torque_B.norm());
    // the force is minus the gradient of V (central differences of the engine's own energy)
    const Vec3 f_N = R * F.head<3>();
    for (int a = 0; a < 3; ++a) {
      VecX qp = q, qm = q;
      const double h = 1.0;  // m, on 7000 km
      qp(a) += h, qm(a) -= h;
      const double dV = (engine.energy(0.0, qp, u).V - engine.energy(0.0, qm, u).V) / (2 * h);
      CHECK(std::abs(-dV - f_N(a)) <= 1e-7 * f_N.norm());
    }
    // the point-mass part dominates: mu m / r^2 toward the centre
    CHECK(std::abs(f_N.dot(-rh) - kMu * 500.0 / r.squaredNorm()) <= 1e-6 * kMu * 500.0 / r.squaredNorm());
  }
}

TEST_CASE("central gravity: a rigid body on an e = 0.1 orbit follows Kepler's equation over 10 orbits", "[central]") {
  const OrbitElements el{7.2e6, 0.1, 0.5, 0.3, 0.8, 0.4};
  const OrbitState s0 = state_from_elements(kMu, el);
  // isotropic inertia: no coupling of the attitude into the orbit (MacCullagh's term vanishes)
  const Model model = load_model(test::write_temp("kepler.yaml", R"(name: kepler
gravity: {central: {mu: 3.986004418e14}}
bodies:
  - {name: sat, parent: ground, joint: {type: free}, mass: 100.0, inertia: [10.0, 10.0, 10.0, 0, 0, 0]}
)"));
  GenericEngine engine(model);
  State s = initial_state(model);
  s.q.head<3>() = s0.r_N;
  s.u.head<3>() = s0.v_N;  // identity attitude: body axes are N's
  SimulationOptions o;
  const double T = orbital_period(kMu, el.a);
  o.t_end = 10 * T;
  o.dt_out = T / 20;
  o.integrator.kind = IntegratorKind::rkf78;
  o.integrator.rtol = 1e-13;
  o.integrator.atol = 1e-6;  // m and m/s: 1e-13 of 7e6 m
  RowTable rows;
  simulate(engine, s, o, rows);
  const auto t = rows.column("t"), x = rows.column("sat.x"), y = rows.column("sat.y"), z = rows.column("sat.z");
  double worst = 0.0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    OrbitElements now = el;
    now.nu = true_anomaly_at(kMu, el, t[k]);
    const OrbitState ref = state_from_elements(kMu, now);
    worst = std::max(worst, (Vec3(x[k], y[k], z[k]) - ref.r_N).norm() / ref.r_N.norm());
  }
  INFO("10 orbits, e = 0.1: largest relative position error against Kepler " << worst);
  CHECK(worst <= 1e-8);
}

TEST_CASE("central gravity: a flexible spinning spacecraft keeps E and H over orbits, with J2, E and H_z", "[central]") {
  const double r0 = 7.0e6, v0 = std::sqrt(kMu / r0);
  const std::string beam = R"(  - name: boom
    parent: sat
    joint: {type: fixed, position: [0.5, 0, 0]}
    flexible:
      beam: {length: 4.0, direction: x, mass_per_length: 2.0, EI: [900.0, 600.0], elements: 6, modes: 2}
)";
  const std::string initial = "initial:\n  q: {sat.x: " + std::to_string(r0) + ", boom.eta1: 0.02}\n  u: {sat.vy: " +
                              std::to_string(v0) + ", sat.wz: 0.01, sat.wx: 0.002}\n";
  SECTION("no J2: E and H about N's origin") {
    const Model model = load_model(test::write_temp("flex_orbit.yaml", sat("{central: {mu: 3.986004418e14}}", beam, initial)));
    const double T = 2 * M_PI * std::sqrt(r0 * r0 * r0 / kMu);
    const test::Drift d = test::run_invariants(model, 2 * T, IntegratorKind::rkf78, 1e-12);
    INFO("E drift " << d.energy << ", H drift " << d.H);
    CHECK(d.energy <= 1e-11);
    CHECK(d.H <= 1e-11);
  }
  SECTION("J2: E and H_z") {
    const Model model = load_model(test::write_temp(
        "flex_j2.yaml", sat("{central: {mu: 3.986004418e14, J2: 1.08262668e-3, radius: 6378137.0}}", beam, initial)));
    GenericEngine engine(model);
    SimulationOptions o;
    const double T = 2 * M_PI * std::sqrt(r0 * r0 * r0 / kMu);
    o.t_end = T;
    o.dt_out = T / 50;
    o.integrator.kind = IntegratorKind::rkf78;
    o.integrator.rtol = 1e-12;
    o.integrator.atol = 1e-9;
    std::vector<double> E, Hz;
    RowTable rows;
    simulate(engine, initial_state(model), o, rows);
    const auto t = rows.column("t");
    double e0 = 0, h0 = 0, dE = 0, dH = 0, scale = 0;
    for (std::size_t k = 0; k < t.size(); ++k) {
      VecX q(model.nq), u(model.nu);
      for (int i = 0; i < model.nq; ++i) q(i) = rows.at(k, 1 + i);
      for (int i = 0; i < model.nu; ++i) u(i) = rows.at(k, 1 + model.nq + i);
      const EnergyValues en = engine.energy(t[k], q, u);
      const double h = engine.momentum(t[k], q, u).H_N.z();
      if (k == 0) e0 = en.T + en.V, h0 = h;
      scale = std::max(scale, en.T + std::abs(en.V));
      dE = std::max(dE, std::abs(en.T + en.V - e0));
      dH = std::max(dH, std::abs(h - h0));
    }
    INFO("J2: E drift " << dE / scale << ", H_z drift " << dH / std::abs(h0));
    CHECK(dE / scale <= 1e-11);
    CHECK(dH / std::abs(h0) <= 1e-11);
  }
}

TEST_CASE("central gravity: refused inputs name file, line and field", "[central]") {
  auto refused = [](const std::string& text, const std::string& what) {
    const std::string p = test::write_temp("bad_central.yaml", text);
    CHECK_THROWS_WITH(load_model(p), Catch::Contains(what));
  };
  refused(sat("{central: {mu: -3.9e14}}"), "gravity.central.mu");
  refused(sat("{central: {mu: 3.9e14, J2: 1.0e-3}}"), "gravity.central.radius");
  refused(sat("{central: {mu: 3.9e14, spin: 1}}"), "unknown key 'spin'");
  refused(R"(name: grounded
gravity: {central: {mu: 3.986e14}}
bodies:
  - {name: arm, parent: ground, joint: {type: revolute, axis: [0, 0, 1]}, mass: 1.0, inertia: [1, 1, 1, 0, 0, 0]}
)", "expected a free root joint");
}

TEST_CASE("initial: orbit: the system's centre of mass on the orbit, attitude: lvlh aligned and turning", "[central]") {
  const OrbitElements el{7.1e6, 0.05, 0.9, 0.4, 1.2, 0.7};
  const std::string text = R"(name: placed
gravity: {central: {mu: 3.986004418e14}}
bodies:
  - {name: bus, parent: ground, joint: {type: free}, mass: 200.0, com: [0.1, -0.05, 0.2], inertia: [80, 90, 70, 1, 2, 3]}
  - {name: arm, parent: bus, joint: {type: revolute, axis: [0, 1, 0], position: [1.0, 0, 0]}, mass: 20.0,
     com: [1.5, 0, 0], inertia: [1, 5, 5, 0, 0, 0]}
initial:
  q: {arm.angle: 0.3}
  u: {arm.angle_rate: 0.2}
  orbit: {a: 7.1e6, e: 0.05, i: 0.9, raan: 0.4, argp: 1.2, nu: 0.7, attitude: lvlh}
)";
  const Model model = load_model(test::write_temp("placed.yaml", text));
  const State s = initial_state(model);
  const OrbitState target = state_from_elements(kMu, el);
  GenericEngine engine(model);
  // centre of mass and its velocity: from the engine's momentum and a first-moment sum of its energy-free parts
  const MomentumValues P = engine.momentum(0.0, s.q, s.u);
  CHECK((P.p_N / 220.0 - target.v_N).norm() <= 1e-12 * target.v_N.norm());
  const Vec3 x_bus = s.q.head<3>();
  const Eigen::Quaterniond Q(s.q(3), s.q(4), s.q(5), s.q(6));
  const Mat3 R_NB = Q.toRotationMatrix();
  CHECK((R_NB - lvlh_frame(target)).norm() <= 1e-12);
  CHECK((R_NB * s.u.segment<3>(3) - lvlh_rate_N(target)).norm() <= 1e-12 * lvlh_rate_N(target).norm());
  // the arm's com at angle 0.3 about y from [1, 0, 0] + R_y(0.3) [1.5, 0, 0]
  const Vec3 arm_com_B = Vec3(1.0, 0, 0) + Eigen::AngleAxisd(0.3, Vec3::UnitY()) * Vec3(1.5, 0, 0);
  const Vec3 com = x_bus + R_NB * ((200.0 * Vec3(0.1, -0.05, 0.2) + 20.0 * arm_com_B) / 220.0);
  CHECK((com - target.r_N).norm() <= 1e-9 * target.r_N.norm());
  // the joint's own speed is kept
  CHECK(s.u(model.speed_index("arm.angle_rate")) == 0.2);
}

TEST_CASE("initial: orbit: refused without a central field, for e >= 1, a <= 0, or with the root's position", "[central]") {
  auto refused = [](const std::string& text, const std::string& what) {
    CHECK_THROWS_WITH(load_model(test::write_temp("bad_orbit.yaml", text)), Catch::Contains(what));
  };
  const std::string body = "\nbodies:\n  - {name: sat, parent: ground, joint: {type: free}, mass: 1.0, inertia: [1, 1, 1, 0, 0, 0]}\n";
  refused("name: o" + body + "initial:\n  orbit: {a: 7.0e6, e: 0.1}\n", "an orbit needs a central field");
  refused("name: o\ngravity: {central: {mu: 3.986e14}}" + body + "initial:\n  orbit: {a: 7.0e6, e: 1.0}\n",
          "initial.orbit.e");
  refused("name: o\ngravity: {central: {mu: 3.986e14}}" + body + "initial:\n  orbit: {a: -7.0e6, e: 0.1}\n",
          "initial.orbit.a");
  refused("name: o\ngravity: {central: {mu: 3.986e14}}" + body +
              "initial:\n  q: {sat.x: 7.0e6}\n  orbit: {a: 7.0e6, e: 0.1}\n",
          "'sat.x' is set by initial.orbit");
  refused("name: o\ngravity: {central: {mu: 3.986e14}}" + body +
              "initial:\n  u: {sat.wz: 0.1}\n  orbit: {a: 7.0e6, e: 0.1, attitude: lvlh}\n",
          "initial.u.sat.wz");
}

TEST_CASE("initial: orbit: attitude_offset and rate_offset start the root off the orbit frame (R_NB = R_NL R_LB, "
          "w_B = R_BL w_L + rate_offset)",
          "[central]") {
  const OrbitElements el{6.978e6, 0.001, 1.7, 0.3, 0.0, 0.0};
  const OrbitState target = state_from_elements(kMu, el);
  const std::string head = R"(name: offset
gravity: {central: {mu: 3.986004418e14}}
bodies:
  - {name: bus, parent: ground, joint: {type: free}, mass: 200.0, com: [0.1, -0.05, 0.2], inertia: [80, 90, 70, 1, 2, 3]}
initial:
  orbit: {a: 6.978e6, e: 0.001, i: 1.7, raan: 0.3, argp: 0.0, nu: 0.0, attitude: lvlh,
)";
  const Eigen::Quaterniond Q_LB = Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2).normalized();
  const Vec3 rate(1.0e-3, -2.0e-3, 5.0e-4);
  struct Case {
    std::string keys;
    Mat3 R_LB;
    Vec3 rate;
  };
  for (const Case& c : std::vector<Case>{
           {fmt::format("attitude_offset: {{quaternion: [{}, {}, {}, {}]}}, rate_offset: [1.0e-3, -2.0e-3, 5.0e-4]}}",
                        Q_LB.w(), Q_LB.x(), Q_LB.y(), Q_LB.z()),
            Q_LB.toRotationMatrix(), rate},
           {"attitude_offset: {rpy: [0.0, 0.05, 0.0]}}", Eigen::AngleAxisd(0.05, Vec3::UnitY()).toRotationMatrix(),
            Vec3::Zero()},
           {"rate_offset: [0.0, 0.0, 1.0e-3]}", Mat3::Identity(), Vec3(0, 0, 1e-3)}}) {
    INFO(c.keys);
    const Model model = load_model(test::write_temp("offset.yaml", head + "          " + c.keys + "\n"));
    const State s = initial_state(model);
    const Mat3 R_NB = Eigen::Quaterniond(s.q(3), s.q(4), s.q(5), s.q(6)).toRotationMatrix();
    const Mat3 R_NL = lvlh_frame(target);
    CHECK((R_NB - R_NL * c.R_LB).norm() <= 1e-12);
    // the angular velocity relative to the orbit frame, in B, is the offset
    const Vec3 w_rel_B = s.u.segment<3>(3) - R_NB.transpose() * lvlh_rate_N(target);
    CHECK((w_rel_B - c.rate).norm() <= 1e-15);
    // the centre of mass is still on the orbit, with the orbit's velocity
    GenericEngine engine(model);
    CHECK((engine.momentum(0.0, s.q, s.u).p_N / 200.0 - target.v_N).norm() <= 1e-12 * target.v_N.norm());
    const Vec3 com = s.q.head<3>() + R_NB * Vec3(0.1, -0.05, 0.2);
    CHECK((com - target.r_N).norm() <= 1e-9 * target.r_N.norm());
  }
  // without attitude: lvlh, either offset is refused, with its line and field
  const std::string plain = R"(name: offset
gravity: {central: {mu: 3.986004418e14}}
bodies:
  - {name: bus, parent: ground, joint: {type: free}, mass: 200.0, inertia: [80, 90, 70, 0, 0, 0]}
initial:
  orbit: {a: 6.978e6, e: 0.001, )";
  CHECK_THROWS_WITH(load_model(test::write_temp("offset_bad.yaml", plain + "rate_offset: [0, 0, 1.0e-3]}\n")),
                    Catch::Contains(":6: initial.orbit.rate_offset: given without attitude: lvlh"));
  CHECK_THROWS_WITH(load_model(test::write_temp("offset_bad.yaml", plain + "attitude_offset: {rpy: [0, 0.1, 0]}}\n")),
                    Catch::Contains("initial.orbit.attitude_offset: given without attitude: lvlh"));
  CHECK_THROWS_WITH(
      load_model(test::write_temp("offset_bad.yaml", plain + "attitude: lvlh, rate_offset: [0, 1.0e-3]}\n")),
      Catch::Contains("initial.orbit.rate_offset"));
  CHECK_THROWS_WITH(
      load_model(test::write_temp("offset_bad.yaml", plain + "attitude: lvlh, attitude_offset: {rpy: [0, 0.1]}}\n")),
      Catch::Contains("initial.orbit.attitude_offset.rpy"));
}
