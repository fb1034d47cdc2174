// Locks and events (model-format.md "Locks and events", dynamics.md "Locks"):
// the reduced equations against the same model with the joint made fixed,
// the plastic latch against the closed form of a rigid-body impact, event
// location against the pendulum's elliptic-integral closed form in every
// integrator family, a release and a separation, and the refusals.
#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <map>

#include <cmath>
#include <sstream>

#include "engine/generic_engine.hpp"
#include "engine/locks.hpp"
#include "model/diagnostics.hpp"
#include "engine/load_model.hpp"
#include "model/rotation.hpp"
#include "model/state_io.hpp"
#include "sim/linearize.hpp"
#include "sim/simulate.hpp"
#include "sim/sweep.hpp"
#include "model/sweep_spec.hpp"

#include <set>
#include "tests/support/test_support.hpp"
#include "tests/support/tolerances.hpp"

using namespace kanegen;

namespace {

/// The rows of a simulate() CSV by column name.
struct Csv {
  std::vector<std::string> cols;
  std::vector<std::vector<double>> rows;
  int col(const std::string& n) const {
    for (std::size_t i = 0; i < cols.size(); ++i)
      if (cols[i] == n) return static_cast<int>(i);
    FAIL("no column " << n);
    return -1;
  }
};

Csv parse_csv(const std::string& text) {
  Csv c;
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  std::stringstream h(line);
  for (std::string cell; std::getline(h, cell, ',');) c.cols.push_back(cell);
  while (std::getline(in, line)) {
    std::vector<double> r;
    std::stringstream s(line);
    for (std::string cell; std::getline(s, cell, ',');) r.push_back(std::stod(cell));
    c.rows.push_back(r);
  }
  return c;
}

/// A free bus (full inertia, off-centre) with a hinged panel (arbitrary axis,
/// spring driving it open), the panel stowed (locked) and released at 0.5 s,
/// latched at 1.2 rad; no gravity: p and H hold.
const char* kLatchModel = R"(
name: latch_panel
bodies:
  - name: bus
    parent: ground
    mass: 120
    com: [0.05, -0.02, 0.1]
    inertia: [[20, 0.4, -0.3], [0.4, 30, 0.2], [-0.3, 0.2, 25]]
    joint: {type: free}
  - name: panel
    parent: bus
    mass: 6
    com: [0.6, 0.05, 0]
    inertia: [[0.3, 0.01, 0], [0.01, 0.7, 0.02], [0, 0.02, 0.9]]
    joint: {type: revolute, axis: [0.36, 0.48, 0.8], position: [1.0, 0.2, -0.1], rotation: {rpy: [0.2, -0.1, 0.3]},
            stiffness: 3.0, rest: 2.5, locked: true}
initial:
  u: {bus.vx: 0.3, bus.vy: -0.1, bus.wx: 0.02, bus.wy: -0.01, bus.wz: 0.05}
outputs: [energy, momentum, reactions]
events:
  - {name: deploy, at: 0.5, release: [panel]}
  - {name: latch, when: {coordinate: panel.angle, reaches: 1.2}, lock: [panel]}
)";

/// Kinetic energy of the whole system moving as one rigid body with linear
/// momentum p and angular momentum H (about N's origin), from its mass, centre
/// of mass r_c and central inertia I_c (N components): the energy a perfectly
/// plastic latch leaves (it conserves p and H and leaves no relative motion).
double rigid_energy(double m, const Vec3& r_c, const Mat3& I_c, const Vec3& p, const Vec3& H) {
  const Vec3 H_c = H - r_c.cross(p);
  return 0.5 * p.squaredNorm() / m + 0.5 * H_c.dot(I_c.ldlt().solve(H_c));
}

Mat3 skew(const Vec3& v) {
  Mat3 S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

}  // namespace

TEST_CASE("locks: a latch conserves p and H to round-off and loses the rigid-body impact's energy, the panel stops",
          "[locks]") {
  const Model model = load_model(test::write_temp("latch_panel.yaml", kLatchModel));
  REQUIRE(model.events.size() == 2);
  for (int generated = 0; generated < 2; ++generated) {
    std::unique_ptr<Engine> engine;
    if (generated)
      engine = test::generated_engine(model);
    else
      engine = std::make_unique<GenericEngine>(model);
    SimulationOptions o;
    o.t_end = 4.0;
    o.dt_out = 0.1;
    o.integrator.kind = IntegratorKind::rkf78;
    o.integrator.rtol = 1e-11;
    o.integrator.atol = 1e-13;
    std::ostringstream out;
    const SimulationResult r = simulate(*engine, initial_state(model), o, out);
    REQUIRE(r.events.size() == 2);
    CHECK(r.segments == 3);
    const FiredEvent& latch = r.events[1];
    CHECK(latch.name == "latch");
    const Csv csv = parse_csv(out.str());
    // the two rows at the latch time: just before and just after
    std::size_t before = 0;
    for (std::size_t i = 0; i + 1 < csv.rows.size(); ++i)
      if (csv.rows[i][0] == latch.t && csv.rows[i + 1][0] == latch.t) before = i;
    REQUIRE(before > 0);
    const auto& a = csv.rows[before];
    const auto& b = csv.rows[before + 1];
    CHECK(a[csv.col("panel.angle")] == Approx(1.2).epsilon(1e-14));
    CHECK(b[csv.col("panel.angle_rate")] == 0.0);
    CHECK(std::abs(a[csv.col("panel.angle_rate")]) > 0.1);
    // p and H across the latch (N components), to round-off
    const int nq = model.nq, nu = model.nu;
    VecX xa(nq + nu), xb(nq + nu);
    for (int k = 0; k < nq; ++k) {
      xa(k) = a[csv.col(model.q_names[k])];
      xb(k) = b[csv.col(model.q_names[k])];
    }
    for (int k = 0; k < nu; ++k) {
      xa(nq + k) = a[csv.col(model.u_names[k])];
      xb(nq + k) = b[csv.col(model.u_names[k])];
    }
    GenericEngine measure(model);
    const MomentumValues Pa = measure.momentum(latch.t, xa.head(nq), xa.tail(nu));
    const MomentumValues Pb = measure.momentum(latch.t, xb.head(nq), xb.tail(nu));
    CHECK(test::rel_err(Pb.p_N, Pa.p_N) < 1e-14);
    CHECK(test::rel_err(Pb.H_N, Pa.H_N) < 1e-14);
    // the energy lost against the closed form: after the latch, one rigid body
    const EnergyValues Ea = measure.energy(latch.t, xa.head(nq), xa.tail(nu));
    const EnergyValues Eb = measure.energy(latch.t, xb.head(nq), xb.tail(nu));
    CHECK(latch.energy_lost == Approx(Ea.T - Eb.T).epsilon(1e-12));
    // the combined body's mass, centre of mass and central inertia from the model's geometry
    const Body& bus = model.bodies[0];
    const Body& panel = model.bodies[1];
    const Eigen::Vector4d quat = xa.segment<4>(3);
    const Mat3 R_NB = Eigen::Quaterniond(quat(0), quat(1), quat(2), quat(3)).normalized().toRotationMatrix();
    const Mat3 R_BP = panel.joint.R_PJ * Eigen::AngleAxisd(1.2, panel.joint.axis_J).toRotationMatrix();
    const Vec3 r_bus = xa.head<3>();
    const Vec3 c_bus = r_bus + R_NB * bus.rigid.com_B;
    const Vec3 c_panel = r_bus + R_NB * (panel.joint.p_PJ + R_BP * panel.rigid.com_B);
    const double m = bus.rigid.mass + panel.rigid.mass;
    const Vec3 r_c = (bus.rigid.mass * c_bus + panel.rigid.mass * c_panel) / m;
    auto shifted = [&](const Mat3& I_c_N, double mi, const Vec3& ci) {
      const Mat3 S = skew(ci - r_c);
      return Mat3(I_c_N - mi * S * S);
    };
    const Mat3 I_c = shifted(R_NB * bus.rigid.I_c_B * R_NB.transpose(), bus.rigid.mass, c_bus) +
                     shifted(R_NB * R_BP * panel.rigid.I_c_B * R_BP.transpose() * R_NB.transpose(), panel.rigid.mass,
                             c_panel);
    const double T_after = rigid_energy(m, r_c, I_c, Pa.p_N, Pa.H_N);
    CHECK(Eb.T == Approx(T_after).epsilon(1e-12));
    CHECK(latch.energy_lost == Approx(Ea.T - T_after).epsilon(1e-10));
    CHECK(latch.energy_lost > 0.01 * Ea.T);
    // the release changed no speed
    CHECK(r.events[0].u_after == r.events[0].u_before);
    // energy drift measured between events stays at integration error
    CHECK(r.quality.energy_drift < 1e-8);
    CHECK(r.quality.H_drift < 1e-8);
  }
}

TEST_CASE("events: a released pendulum latched at the bottom crosses at the closed-form time in every integrator family",
          "[locks][events]") {
  // a physical pendulum (rigid body about a pin, gravity -y), from rest at
  // theta0: the quarter period is K(sin(theta0/2)) sqrt(I_O / (m g L))
  const double theta0 = 1.1, m = 2.0, L = 0.8, Izz = 0.05, g = 9.81;
  const Model model = load_model(test::write_temp("pendulum_latch.yaml", fmt::format(R"(
name: pendulum_latch
gravity: [0, -{}, 0]
bodies:
  - name: bob
    parent: ground
    mass: {}
    com: [0, -{}, 0]
    inertia: [[0.03, 0, 0], [0, 0.04, 0], [0, 0, {}]]
    joint: {{type: revolute, axis: [0, 0, 1], locked: true}}
initial:
  q: {{bob.angle: {}}}
events:
  - {{name: drop, at: 0.25, release: [bob]}}
  - {{name: catch, when: {{coordinate: bob.angle, reaches: 0}}, lock: [bob]}}
)", g, m, L, Izz, theta0)));
  const double I_O = Izz + m * L * L;
  const double t_cross = 0.25 + std::comp_ellint_1(std::sin(theta0 / 2)) * std::sqrt(I_O / (m * g * L));
  struct Case {
    IntegratorKind kind;
    double rtol, h;
  };
  for (const Case c : {Case{IntegratorKind::rkf78, 1e-12, 0}, Case{IntegratorKind::dopri5, 1e-12, 0},
                       Case{IntegratorKind::rk4, 0, 1e-3}, Case{IntegratorKind::cvode_bdf, 1e-12, 0},
                       Case{IntegratorKind::cvode_adams, 1e-12, 0}, Case{IntegratorKind::arkode_erk, 1e-12, 0},
                       Case{IntegratorKind::arkode_dirk, 1e-12, 0}}) {
    GenericEngine engine(model);
    SimulationOptions o;
    o.t_end = 2.0;
    o.dt_out = 0.05;
    o.integrator.kind = c.kind;
    if (c.rtol > 0) {
      o.integrator.rtol = c.rtol;
      o.integrator.atol = c.rtol / 100;
    }
    if (c.h > 0) o.integrator.h = c.h;
    std::ostringstream out;
    const SimulationResult r = simulate(engine, initial_state(model), o, out);
    INFO(to_string(c.kind));
    REQUIRE(r.events.size() == 2);
    CHECK(r.events[0].t == 0.25);
    CHECK(std::abs(r.events[1].t - t_cross) < 1e-9);
    // after the catch the pendulum rests at the bottom: every later row
    const Csv csv = parse_csv(out.str());
    for (const auto& row : csv.rows)
      if (row[0] > r.events[1].t) {
        CHECK(row[csv.col("bob.angle")] == Approx(0.0).margin(1e-12));
        CHECK(row[csv.col("bob.angle_rate")] == 0.0);
      }
    // outputs stay on the --dt-out grid (plus the two rows at each event)
    int off_grid = 0;
    for (const auto& row : csv.rows) {
      const double k = row[0] / o.dt_out;
      if (std::abs(k - std::round(k)) > 1e-6) ++off_grid;
    }
    CHECK(off_grid == 2);  // the catch's two rows (the drop at 0.25 is on the grid)
    CHECK(csv.rows.size() == 41 + 1 + 2);
  }
}

TEST_CASE("events: a state event on a quaternion component is refused", "[locks][input]") {
  const std::string path = test::write_temp("quat_event.yaml", R"(name: quat_event
bodies:
  - name: sat
    parent: ground
    mass: 1
    inertia: [1, 2, 3, 0, 0, 0]
    joint: {type: free}
  - name: arm
    parent: sat
    mass: 1
    joint: {type: revolute, axis: [0, 0, 1]}
events:
  - {name: a, when: {coordinate: sat.qz, reaches: 0.5}, lock: [arm]}
)");
  CHECK_THROWS_WITH(load_model(path), Catch::Contains("quat_event.yaml:13: events[0].when.coordinate:") &&
                                          Catch::Contains("component of a unit quaternion"));
}

TEST_CASE("events: a time event exactly at the end time fires (two rows there)", "[locks][events]") {
  const Model model = load_model(test::write_temp("end_event.yaml", R"(name: end_event
gravity: [0, -9.81, 0]
bodies:
  - name: bob
    parent: ground
    mass: 1
    com: [0, -1, 0]
    inertia: [0.01, 0.01, 0.01, 0, 0, 0]
    joint: {type: revolute, axis: [0, 0, 1]}
initial:
  q: {bob.angle: 0.5}
events:
  - {name: stop, at: 1.5, lock: [bob]}
)"));
  GenericEngine engine(model);
  SimulationOptions o;
  o.t_end = 1.5;
  o.dt_out = 0.5;
  o.integrator.kind = IntegratorKind::rkf78;
  std::ostringstream out;
  const SimulationResult r = simulate(engine, initial_state(model), o, out);
  REQUIRE(r.events.size() == 1);
  CHECK(r.events[0].t == 1.5);
  CHECK(r.events[0].energy_lost > 0);  // the swinging bob latched
  const Csv csv = parse_csv(out.str());
  REQUIRE(csv.rows.size() == 5);  // 0, 0.5, 1, and 1.5 before and after
  CHECK(csv.rows[3][0] == 1.5);
  CHECK(csv.rows[4][0] == 1.5);
  CHECK(csv.rows[3][csv.col("bob.angle_rate")] != 0.0);
  CHECK(csv.rows[4][csv.col("bob.angle_rate")] == 0.0);
}

namespace {

/// A chain on a free base, one joint of `type` in the middle, with gravity,
/// springs and a flexible-free mixture; `locked`: that joint locked, or made
/// fixed at the configuration `q_mid` (the rotation composed into its frame).
std::string chain_model(const std::string& mid_joint) {
  return fmt::format(R"(
name: lock_vs_fixed
gravity: [0.3, -9.81, 0.5]
bodies:
  - name: base
    parent: ground
    mass: 10
    com: [0.1, 0, 0.05]
    inertia: [[2, 0.1, 0], [0.1, 3, -0.05], [0, -0.05, 2.5]]
    joint: {{type: free}}
  - name: link1
    parent: base
    mass: 2
    com: [0.3, 0.02, 0]
    inertia: [[0.05, 0, 0.01], [0, 0.2, 0], [0.01, 0, 0.21]]
    joint: {{type: revolute, axis: [0, 0.6, 0.8], position: [0.5, 0, 0], stiffness: 4, damping: 0.2, rest: 0.1}}
  - name: mid
    parent: link1
    mass: 1.5
    com: [0.25, -0.03, 0.02]
    inertia: [[0.03, 0.002, 0], [0.002, 0.1, 0.001], [0, 0.001, 0.11]]
    joint: {}
  - name: tip
    parent: mid
    mass: 0.7
    com: [0.2, 0, 0]
    inertia: [[0.01, 0, 0], [0, 0.03, 0], [0, 0, 0.03]]
    joint: {{type: revolute, axis: [1, 0, 0], position: [0.5, 0, 0.1], damping: 0.1}}
outputs: [reactions]
)",
                     mid_joint);
}

}  // namespace

TEST_CASE("locks: while locked, u-dot and reactions equal those of the model with that joint fixed (both engines)",
          "[locks]") {
  struct Case {
    std::string joint;       ///< the middle joint, free to lock
    std::string fixed;       ///< the same joint fixed at the configuration below
    std::map<std::string, double> q_mid;
  };
  const Mat3 R_PJ = (Eigen::AngleAxisd(0.3, Vec3::UnitZ()) * Eigen::AngleAxisd(-0.2, Vec3::UnitX())).toRotationMatrix();
  const double th = 0.7;
  const Vec3 a = Vec3(1, 2, 2).normalized();
  const Mat3 R_rev = R_PJ * Eigen::AngleAxisd(th, a).toRotationMatrix();
  const Eigen::Quaterniond qb = Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2).normalized();
  const Mat3 R_ball = R_PJ * qb.toRotationMatrix();
  const Vec3 p_free(0.1, -0.2, 0.3);
  auto matrix = [](const Mat3& R) {
    return fmt::format("{{matrix: [[{:.17g}, {:.17g}, {:.17g}], [{:.17g}, {:.17g}, {:.17g}], [{:.17g}, {:.17g}, {:.17g}]]}}",
                       R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2));
  };
  auto quaternion = [](const Mat3& R) {
    const Eigen::Quaterniond q(R);
    return fmt::format("{{quaternion: [{:.17g}, {:.17g}, {:.17g}, {:.17g}]}}", q.w(), q.x(), q.y(), q.z());
  };
  const std::string rot = quaternion(R_PJ);
  const std::vector<Case> cases = {
      {fmt::format("{{type: revolute, axis: [{:.17g}, {:.17g}, {:.17g}], position: [0.6, 0.05, 0], rotation: {}, "
                   "stiffness: 2, rest: 0.3, locked: true}}",
                   a.x(), a.y(), a.z(), rot),
       fmt::format("{{type: fixed, position: [0.6, 0.05, 0], rotation: {}}}", matrix(R_rev)),
       {{"mid.angle", th}}},
      {fmt::format("{{type: ball, position: [0.6, 0.05, 0], rotation: {}, damping: 0.3, locked: true}}", rot),
       fmt::format("{{type: fixed, position: [0.6, 0.05, 0], rotation: {}}}", matrix(R_ball)),
       {{"mid.qw", qb.w()}, {"mid.qx", qb.x()}, {"mid.qy", qb.y()}, {"mid.qz", qb.z()}}},
      {fmt::format("{{type: free, position: [0.6, 0.05, 0], rotation: {}, locked: true}}", rot),
       fmt::format("{{type: fixed, position: [{:.17g}, {:.17g}, {:.17g}], rotation: {}}}",
                   (Vec3(0.6, 0.05, 0) + R_PJ * p_free).x(), (Vec3(0.6, 0.05, 0) + R_PJ * p_free).y(),
                   (Vec3(0.6, 0.05, 0) + R_PJ * p_free).z(), matrix(R_ball)),
       {{"mid.x", p_free.x()}, {"mid.y", p_free.y()}, {"mid.z", p_free.z()}, {"mid.qw", qb.w()}, {"mid.qx", qb.x()},
        {"mid.qy", qb.y()}, {"mid.qz", qb.z()}}},
  };
  for (const Case& c : cases) {
    INFO(c.joint);
    const Model locked = load_model(test::write_temp("lock_vs_fixed_locked.yaml", chain_model(c.joint)));
    const Model fixed = load_model(test::write_temp("lock_vs_fixed_fixed.yaml", chain_model(c.fixed)));
    REQUIRE(locked.bodies[2].joint.locked);
    // one state: the fixed model's q and u, the locked model's the same plus the held joint
    State sf = initial_state(fixed);
    sf.q.head<7>() << 0.2, -0.1, 0.4, 0.8, 0.2, -0.5, 0.26;
    sf.q.segment<4>(3).normalize();
    for (int k = 7; k < fixed.nq; ++k) sf.q(k) = 0.3 + 0.2 * k;
    for (int k = 0; k < fixed.nu; ++k) sf.u(k) = 0.1 * (k + 1) * (k % 2 ? -1 : 1);
    State sl = initial_state(locked);
    for (int k = 0; k < locked.nq; ++k) {
      const std::string& n = locked.q_names[k];
      sl.q(k) = c.q_mid.count(n) ? c.q_mid.at(n) : sf.q(fixed.q_index(n));
    }
    for (int k = 0; k < locked.nu; ++k) {
      const int kf = fixed.u_index(locked.u_names[k]);
      sl.u(k) = kf >= 0 ? sf.u(kf) : 0.0;
    }
    REQUIRE(sl.locked[2] == 1);
    for (int generated = 0; generated < 2; ++generated) {
      INFO((generated ? "generated" : "generic"));
      std::unique_ptr<Engine> el, ef;
      if (generated) {
        el = test::generated_engine(locked);
        ef = test::generated_engine(fixed);
      } else {
        el = std::make_unique<GenericEngine>(locked);
        ef = std::make_unique<GenericEngine>(fixed);
      }
      el->set_locks(sl.locked);
      VecX ud_l, ud_f;
      el->udot(sl.q, sl.u, sl.tau, ud_l);
      ef->udot(sf.q, sf.u, sf.tau, ud_f);
      VecX ud_l_mapped(fixed.nu);
      for (int k = 0; k < locked.nu; ++k) {
        const int kf = fixed.u_index(locked.u_names[k]);
        if (kf >= 0)
          ud_l_mapped(kf) = ud_l(k);
        else
          CHECK(ud_l(k) == 0.0);  // the locked speeds
      }
      CHECK(test::rel_err(ud_l_mapped, ud_f) < test::kRoundoff);
      std::vector<Reaction> rl, rf;
      el->reactions(sl.q, sl.u, ud_l, rl);
      ef->reactions(sf.q, sf.u, ud_f, rf);
      for (std::size_t b = 0; b < rl.size(); ++b) {
        INFO(locked.bodies[b].name);
        CHECK(test::rel_err(rl[b].force_B, rf[b].force_B, 1.0) < test::kReactionRoundoff);
        CHECK(test::rel_err(rl[b].torque_B, rf[b].torque_B, 1.0) < test::kReactionRoundoff);
      }
      // the locking torque: the fixed model's reaction along the joint's axis (revolute)
      if (locked.bodies[2].joint.type == JointType::revolute) {
        const Vec3 axis_B = Eigen::AngleAxisd(th, a).toRotationMatrix().transpose() * a;
        CHECK(rl[2].torque_B.dot(axis_B) == Approx(rf[2].torque_B.dot(axis_B)).epsilon(1e-11));
        CHECK(std::abs(rl[2].torque_B.dot(axis_B)) > 0.1);
      }
      // the full M and F are the free system's, whatever the locks
      MatX M;
      el->mass_matrix(sl.q, M);
      CHECK(M.rows() == locked.nu);
    }
  }
}

TEST_CASE("locks: a locked free joint released moves afterwards as a separate free body, the release changes no speed",
          "[locks][events]") {
  const std::string text = R"(
name: separation
bodies:
  - name: bus
    parent: ground
    mass: 500
    com: [0, 0, 0]
    inertia: [[300, 5, 0], [5, 280, 3], [0, 3, 350]]
    joint: {type: free}
  - name: probe
    parent: bus
    mass: 40
    com: [0, 0, 0]
    inertia: [[4, 0, 0], [0, 5, 0], [0, 0, 6]]
    joint: {type: free, position: [0, 0, 1.5], locked: true}
initial:
  u: {bus.vz: 0.02, bus.wx: 0.01, bus.wz: 0.3}
outputs: [reactions, momentum]
events:
  - {name: separation, at: 2.0, release: [probe]}
)";
  const Model model = load_model(test::write_temp("separation.yaml", text));
  GenericEngine engine(model);
  SimulationOptions o;
  o.t_end = 6.0;
  o.dt_out = 0.5;
  o.integrator.kind = IntegratorKind::rkf78;
  o.integrator.rtol = 1e-12;
  o.integrator.atol = 1e-14;
  std::ostringstream out;
  const SimulationResult r = simulate(engine, initial_state(model), o, out);
  REQUIRE(r.events.size() == 1);
  CHECK(r.events[0].u_after == r.events[0].u_before);
  const Csv csv = parse_csv(out.str());
  // the bus after the separation against a model of the bus alone from its state then
  const Model bus_alone = load_model(test::write_temp("bus_alone.yaml", R"(
name: bus_alone
bodies:
  - name: bus
    parent: ground
    mass: 500
    com: [0, 0, 0]
    inertia: [[300, 5, 0], [5, 280, 3], [0, 3, 350]]
    joint: {type: free}
)"));
  std::size_t after = 0;
  for (std::size_t i = 0; i + 1 < csv.rows.size(); ++i)
    if (csv.rows[i][0] == 2.0 && csv.rows[i + 1][0] == 2.0) after = i + 1;
  REQUIRE(after > 0);
  State s = initial_state(bus_alone);
  s.t = 2.0;
  for (int k = 0; k < bus_alone.nq; ++k) s.q(k) = csv.rows[after][csv.col(bus_alone.q_names[k])];
  for (int k = 0; k < bus_alone.nu; ++k) s.u(k) = csv.rows[after][csv.col(bus_alone.u_names[k])];
  GenericEngine e2(bus_alone);
  std::ostringstream out2;
  simulate(e2, s, o, out2);
  const Csv alone = parse_csv(out2.str());
  REQUIRE(alone.rows.size() == csv.rows.size() - after);
  for (std::size_t i = 0; i < alone.rows.size(); ++i)
    for (const auto& n : bus_alone.q_names)
      CHECK(csv.rows[after + i][csv.col(n)] == Approx(alone.rows[i][alone.col(n)]).margin(1e-10));
  // the probe is acted on by nothing after the separation, and held before it (the bus spins)
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    double f = 0;
    for (const char* c : {"probe.fx", "probe.fy", "probe.fz", "probe.tx", "probe.ty", "probe.tz"})
      f = std::max(f, std::abs(csv.rows[i][csv.col(c)]));
    if (i >= after)
      CHECK(f < 1e-12);
    else
      CHECK(f > 0.05);
  }
}

TEST_CASE("locks: the plastic latch of a two-speed system keeps the free speed's generalized momentum", "[locks]") {
  MatX M(2, 2);
  M << 3.0, 0.8, 0.8, 1.5;
  VecX u(2);
  u << 0.4, -1.2;
  const LatchImpact r = latch_impact(M, u, {1});
  CHECK(r.u_plus(1) == 0.0);
  CHECK(r.u_plus(0) == Approx((3.0 * 0.4 + 0.8 * -1.2) / 3.0).epsilon(1e-15));
  CHECK(r.energy_lost == Approx(0.5 * u.dot(M * u) - 0.5 * 3.0 * r.u_plus(0) * r.u_plus(0)).epsilon(1e-14));
  CHECK(r.energy_lost > 0);
}

TEST_CASE("locks: refused events and locks name the file, line and field", "[locks][input]") {
  const std::string head = R"(name: bad_events
bodies:
  - name: arm
    parent: ground
    mass: 1
    joint: {type: revolute, axis: [0, 0, 1], locked: true}
  - name: hub
    parent: arm
    mass: 1
    joint: {type: revolute, axis: [0, 0, 1], motion: {sine: {amplitude: 0.1, frequency: 1}}}
  - name: plate
    parent: arm
    mass: 1
    joint: {type: fixed, position: [1, 0, 0]}
events:
)";
  struct Bad {
    std::string events, field, says;
  };
  const std::vector<Bad> bad = {
      {"  - {name: a, at: 1, release: [nobody]}\n", "events[0].release[0]", "no body named 'nobody'"},
      {"  - {name: a, at: 1, lock: [hub]}\n", "events[0].lock[0]", "prescribed"},
      {"  - {name: a, at: 1, lock: [plate]}\n", "events[0].lock[0]", "no degree of freedom"},
      {"  - {name: a, when: {coordinate: arm.angle, reaches: 1}, release: [arm]}\n"
       "  - {name: b, when: {coordinate: arm.angle, reaches: 2}, lock: [plate]}\n",
       "events[1].lock[0]", "no degree of freedom"},
      {"  - {name: a, when: {coordinate: arm.angle, reaches: 1}, lock: [arm]}\n", "events[0].when.coordinate",
       "locked from the start and no event releases it"},
      {"  - {name: a, when: {coordinate: hub.angle, reaches: 1}, lock: [arm]}\n", "events[0].when.coordinate",
       "prescribed"},
      {"  - {name: a, at: .inf, release: [arm]}\n", "events[0].at", "not finite"},
      {"  - {name: a, at: 1, lock: [arm]}\n", "events[0].lock", "already locked"},
      {"  - {name: a, at: 1, release: [arm]}\n  - {name: b, at: 2, release: [arm]}\n", "events[1].release",
       "already free"},
      {"  - {name: a, release: [arm]}\n", "events[0]", "no trigger"},
      {"  - {name: a, at: 1}\n", "events[0]", "no action"},
      {"  - {name: a, at: 1, release: []}\n", "events[0].release", "an empty list"},
      {"  - {name: a, at: 1, release: [arm], lock: []}\n", "events[0].lock", "an empty list"},
      {"  - {name: a, at: 1, release: [arm]}\n  - {name: a, at: 2, lock: [arm]}\n", "events[1].name", "unique"},
  };
  for (const Bad& b : bad) {
    INFO(b.events);
    const std::string path = test::write_temp("bad_events.yaml", head + b.events);
    try {
      load_model(path);
      FAIL("accepted");
    } catch (const InputError& e) {
      const std::string what = e.what();
      INFO(what);
      CHECK(what.find("bad_events.yaml:") != std::string::npos);
      CHECK(what.find(b.field + ":") != std::string::npos);
      CHECK(what.find(b.says) != std::string::npos);
    }
  }
  // a lock key where it cannot be
  for (const auto& [joint, says] : std::vector<std::pair<std::string, std::string>>{
           {"{type: fixed, locked: true}", "no degree of freedom"},
           {"{type: revolute, axis: [0, 0, 1], motion: {sine: {amplitude: 0.1, frequency: 1}}, locked: true}",
            "prescribed joint cannot be locked"}}) {
    const std::string path = test::write_temp("bad_lock.yaml", "name: bad_lock\nbodies:\n  - name: a\n    parent: ground\n"
                                                               "    mass: 1\n    joint: " + joint + "\n");
    try {
      load_model(path);
      FAIL("accepted " << joint);
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find("bad_lock.yaml:6: bodies[0].joint.locked:") != std::string::npos);
      CHECK(std::string(e.what()).find(says) != std::string::npos);
    }
  }
  // a locked joint with an initial speed; a STATE.json locking a moving joint
  const std::string moving = "name: moving\nbodies:\n  - name: a\n    parent: ground\n    mass: 1\n"
                             "    joint: {type: revolute, axis: [0, 0, 1], locked: true}\ninitial:\n  u: {a.angle_rate: 0.5}\n";
  CHECK_THROWS_WITH(load_model(test::write_temp("moving.yaml", moving)),
                    Catch::Contains("moving.yaml:8: initial.u.a.angle_rate:") && Catch::Contains("locked"));
  const Model free_arm = load_model(test::write_temp("free_arm.yaml", "name: free_arm\nbodies:\n  - name: a\n    parent: "
                                                                      "ground\n    mass: 1\n    joint: {type: revolute, "
                                                                      "axis: [0, 0, 1]}\n"));
  CHECK_THROWS_WITH(load_state(free_arm, test::write_temp("locked_state.json",
                                                          R"({"u": {"a.angle_rate": 0.5}, "locked": ["a"]})")),
                    Catch::Contains("u.a.angle_rate") && Catch::Contains("locked"));
  const State s = load_state(free_arm, test::write_temp("locked_state2.json", R"({"locked": ["a"]})"));
  CHECK(s.locked[0] == 1);
}

TEST_CASE("locks: linearize at a state with a joint locked gives the model with that joint fixed", "[locks][linearize]") {
  // in both engines: the generic by central differences, the generated exactly (the free system's dual-number
  // Jacobian projected onto the reduced system, sim/linearize.cpp); the free joints moving, so the locking
  // torque carries gravity, springs and the coupling of the motion
  const double th = 0.7;
  const std::string locked_joint =
      "{type: revolute, axis: [0, 0, 1], position: [0.6, 0.05, 0], stiffness: 2, rest: 0.3, locked: true}";
  const std::string fixed_joint =
      fmt::format("{{type: fixed, position: [0.6, 0.05, 0], rotation: {{axis_angle: [[0, 0, 1], {:.17g}]}}}}", th);
  // a named input on a free joint beyond the locked one: its column of B is P times the free system's
  // and sensors beyond it that read accelerations: an accelerometer and the tip's joint reaction
  const std::string input = "inputs:\n  - {name: push, type: joint_torque, joint: tip}\n";
  auto with_sensors = [&](std::string m) {
    const std::string was = "outputs: [reactions]\n";
    m.replace(m.find(was), was.size(),
              "outputs:\n  - reactions\n  - {name: imu, type: specific_force, body: tip, point: [0.1, 0.05, 0]}\n"
              "  - {name: hold, type: reaction, joint: tip}\n");
    return m + input;
  };
  const Model locked = load_model(test::write_temp("lin_locked.yaml", with_sensors(chain_model(locked_joint))));
  const Model fixed = load_model(test::write_temp("lin_fixed.yaml", with_sensors(chain_model(fixed_joint))));
  State sl = initial_state(locked), sf = initial_state(fixed);
  sl.q(locked.q_index("mid.angle")) = th;
  for (const auto& [n, q, u] : {std::tuple{"link1.angle", 0.4, 0.3}, std::tuple{"tip.angle", -0.2, -0.5}}) {
    sl.q(locked.q_index(n)) = sf.q(fixed.q_index(n)) = q;
    sl.u(locked.u_index(std::string(n) + "_rate")) = sf.u(fixed.u_index(std::string(n) + "_rate")) = u;
  }
  for (int k = 0; k < 3; ++k) sl.u(k) = sf.u(k) = 0.1 * (k + 1);  // the base's angular velocity
  for (const bool generated : {false, true}) {
    INFO((generated ? "generated" : "generic"));
    std::unique_ptr<Engine> el, ef;
    if (generated) {
      el = test::generated_engine(locked), ef = test::generated_engine(fixed);
    } else {
      el = std::make_unique<GenericEngine>(locked), ef = std::make_unique<GenericEngine>(fixed);
    }
    LinearizeOptions o;  // the named input and every generalized force
    o.inputs.push_back("push");
    for (const std::string& u : locked.u_names) o.inputs.push_back("tau." + u);
    const LinearModel a = linearize(*el, sl, o);
    LinearizeOptions of;
    of.inputs.push_back("push");
    for (const std::string& u : fixed.u_names) of.inputs.push_back("tau." + u);
    const LinearModel b = linearize(*ef, sf, of);
    INFO(a.method);
    CHECK(a.method.rfind(generated ? "exact" : "central", 0) == 0);
    REQUIRE(a.state_names == b.state_names);
    CHECK(test::rel_err(a.A, b.A) < (generated ? 1e-12 : 1e-6));
    // the outputs while locked are the reduced motion's: the fixed model's, and so are C and D
    {
      VecX ya, yb;
      const ScopedLocks held(*el, sl.locked);
      el->set_inputs(sl.w), ef->set_inputs(sf.w);
      el->outputs(sl.t, sl.q, sl.u, sl.tau, ya);
      ef->outputs(sf.t, sf.q, sf.u, sf.tau, yb);
      CHECK(test::rel_err(ya, yb, 1.0) < 1e-12);
    }
    REQUIRE(a.output_names == b.output_names);
    CHECK(test::rel_err(a.y0, b.y0, 1.0) < 1e-12);
    CHECK(test::rel_err(a.C, b.C) < (generated ? 1e-12 : 1e-6));
    for (std::size_t k = 0; k < a.input_names.size(); ++k) {
      const auto it = std::find(b.input_names.begin(), b.input_names.end(), a.input_names[k]);
      INFO(a.input_names[k]);
      if (it == b.input_names.end())  // the locked speed's torque: held by the lock, no output sees it
        CHECK(a.D.col(k).cwiseAbs().maxCoeff() <= (generated ? 1e-12 : 1e-6) * a.D.cwiseAbs().maxCoeff());
      else
        CHECK(test::rel_err(a.D.col(k), b.D.col(it - b.input_names.begin()), 1.0) < (generated ? 1e-12 : 1e-6));
    }
    // the named input's column, and the tau columns: M_ff^-1 against the fixed model's M^-1 (the locked
    // speed's column is zero)
    REQUIRE(a.input_names[0] == "push");
    CHECK(!a.B.col(0).isZero(0.0));
    for (std::size_t k = 0; k < a.input_names.size(); ++k) {
      const auto it = std::find(b.input_names.begin(), b.input_names.end(), a.input_names[k]);
      if (it == b.input_names.end()) {
        CHECK(a.B.col(k).isZero(0.0));
        continue;
      }
      // the named input's column by differences in the generic engine (u_dot is linear in it: round-off only)
      const double tol = k == 0 && !generated ? 1e-7 : 1e-9;
      CHECK(test::rel_err(a.B.col(k), b.B.col(it - b.input_names.begin()), 1.0) < tol);
    }
    CHECK(!el->has_locks());  // the engine's locks are back as they were
  }
}

TEST_CASE("events: a sweep disperses an event's time and records another event's time and energy lost",
          "[locks][events][sweep]") {
  // the pendulum of the crossing test: released at a dispersed time, caught at the bottom a quarter period later
  const double theta0 = 0.9, m = 1.5, L = 0.6, Izz = 0.02, g = 9.81;
  const std::string model = test::write_temp("sweep_latch.yaml", fmt::format(R"(
name: sweep_latch
gravity: [0, -{}, 0]
bodies:
  - name: bob
    parent: ground
    mass: {}
    com: [0, -{}, 0]
    inertia: [[0.01, 0, 0], [0, 0.01, 0], [0, 0, {}]]
    joint: {{type: revolute, axis: [0, 0, 1], locked: true}}
initial:
  q: {{bob.angle: {}}}
events:
  - {{name: drop, at: 0.5, release: [bob]}}
  - {{name: catch, when: {{coordinate: bob.angle, reaches: 0}}, lock: [bob]}}
)", g, m, L, Izz, theta0));
  const std::string sweep = test::write_temp("sweep_latch.sweep.yaml", R"(
model: sweep_latch.yaml
runs: 4
seed: 3
t_end: 3.0
dt_out: 0.1
integrator: rkf78
rtol: 1.0e-11
atol: 1.0e-13
engine: generic
dispersions:
  - {parameter: events.drop.at, distribution: uniform, low: -0.4, high: 0.4}
metrics:
  - {name: t_catch, column: event.catch.t}
  - {name: lost, column: event.catch.energy_lost}
)");
  const SweepPlan plan = plan_sweep(load_sweep_spec(sweep));
  const double I_O = Izz + m * L * L;
  const double quarter = std::comp_ellint_1(std::sin(theta0 / 2)) * std::sqrt(I_O / (m * g * L));
  // the catch takes the whole swing energy: the drop from theta0 to the bottom
  const double swing = m * g * L * (1 - std::cos(theta0));
  GenericEngine engine(plan.model);
  std::set<double> drops;
  for (long i = 0; i < 4; ++i) {
    const RunResult r = run_one(engine, plan, i);
    REQUIRE(r.ok());
    drops.insert(r.values[0]);
    CHECK(std::abs(r.metrics[0] - (r.values[0] + quarter)) < 1e-9);
    CHECK(r.metrics[1] == Approx(swing).epsilon(1e-8));
  }
  CHECK(drops.size() == 4);  // the drop time was dispersed
  // refused: an unknown event, .at of a crossing event
  const std::string bad = test::write_temp("sweep_latch_bad.sweep.yaml", R"(
model: sweep_latch.yaml
runs: 2
t_end: 1.0
dispersions:
  - {parameter: events.catch.at, distribution: uniform, low: -0.1, high: 0.1}
  - {parameter: events.nothing.at, distribution: uniform, low: -0.1, high: 0.1}
metrics:
  - {name: t_catch, column: event.catch.t}
)");
  try {
    plan_sweep(load_sweep_spec(bad));
    FAIL("accepted");
  } catch (const InputError& e) {
    const std::string w = e.what();
    INFO(w);
    CHECK(w.find("dispersions[0].parameter: 'events.catch.at'") != std::string::npos);
    CHECK(w.find("it has no event 'nothing'") != std::string::npos);
  }
}

TEST_CASE("locks: a latch in orbit loses the plastic-impact energy of the same motion about the centre of mass "
          "(Galilean invariance), to 1e-9, though T is 1e10 times larger",
          "[locks][central]") {
  const Model model = load_model(test::write_temp("orbit_latch.yaml", R"(name: orbit_latch
gravity:
  central: {mu: 3.986004418e14}
bodies:
  - {name: bus, parent: ground, joint: {type: free}, mass: 1000.0, com: [0.02, 0, 0.01], inertia: [1500, 1200, 1000, 0, 0, 0]}
  - name: panel
    parent: bus
    joint: {type: revolute, axis: [0, 1, 0], position: [0.8, 0, 0]}
    mass: 20.0
    com: [1.0, 0, 0]
    inertia: [2.0, 7.0, 6.0, 0, 0, 0]
initial:
  q: {panel.angle: 0.3}
  u: {panel.angle_rate: 0.01}
  orbit: {a: 7.0e6, e: 0.01, i: 0.9, raan: 0.2, argp: 0.4, nu: 1.1, attitude: lvlh}
)"));
  GenericEngine engine(model);
  const State s = initial_state(model);
  const std::vector<int> locked = {model.u_index("panel.angle_rate")};
  MatX M;
  engine.mass_matrix(s.q, M);
  const double T = 0.5 * s.u.dot(M * s.u);
  REQUIRE(T > 1e10);
  const LatchImpact in_orbit = latch_impact(M, s.u, locked);
  // the same motion seen from the centre of mass's frame, the bus at N's origin: T is small, T- - T+ direct
  const double mass = 1020.0;
  const Vec3 v_c = engine.momentum(s.q, s.u).p_N / mass;
  VecX q_c = s.q, u_c = s.u;
  q_c.head<3>().setZero();
  const Mat3 R_NB = Eigen::Quaterniond(s.q(3), s.q(4), s.q(5), s.q(6)).normalized().toRotationMatrix();
  u_c.head<3>() -= R_NB.transpose() * v_c;
  MatX M_c;
  engine.mass_matrix(q_c, M_c);
  CHECK(engine.momentum(q_c, u_c).p_N.norm() <= 1e-9 * mass * v_c.norm());
  const std::vector<int> f = {0, 1, 2, 3, 4, 5};
  const Eigen::VectorXd p_f = (M_c * u_c).head(6);
  VecX u_plus = VecX::Zero(7);
  u_plus.head(6) = M_c.topLeftCorner(6, 6).llt().solve(p_f);
  const double lost_direct = 0.5 * u_c.dot(M_c * u_c) - 0.5 * u_plus.dot(M_c * u_plus);
  INFO("in orbit " << in_orbit.energy_lost << " J, about the centre of mass " << lost_direct << " J");
  REQUIRE(lost_direct > 1e-5);
  CHECK(std::abs(in_orbit.energy_lost - lost_direct) <= 1e-9 * lost_direct);
  // and the speeds after it: the same jump
  CHECK((in_orbit.u_plus - s.u - (u_plus - u_c)).norm() <= 1e-12 * s.u.norm());
}
