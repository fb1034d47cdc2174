// Orbit-frame sensors (docs/gnc.md, "Orbit-frame sensors"; templates/orbit_frame.inc)
// in both engines: at an orbit's initial state they read back the elements, the
// centre of mass and the LVLH offsets the model gave; along the motion the
// attitude relative to LVLH turns at the relative rate they report; on a
// Kepler orbit the osculating elements stay put and the anomaly follows
// Kepler's equation over 10 orbits.
#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <complex>
#include <iomanip>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/orbit.hpp"
#include "sim/row_sink.hpp"
#include "sim/simulate.hpp"
#include "tests/support/librations.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

using test::kMu;

const char* kSensors = R"(
outputs:
  - {name: att,  type: attitude_lvlh,         body: bus}
  - {name: rate, type: angular_velocity_lvlh, body: bus}
  - {name: com,  type: com_position}
  - {name: comv, type: com_velocity}
  - {name: osc,  type: orbit_elements}
)";

/// A bus with an offset centre of mass and a hinged arm, so that the system's
/// centre of mass is neither the bus's origin nor its centre of mass.
std::string orbiter(const std::string& orbit_keys, const std::string& gravity = "{central: {mu: 3.986004418e14}}") {
  return "name: orbit_sensors\ngravity: " + gravity + R"(
bodies:
  - {name: bus, parent: ground, joint: {type: free}, mass: 200.0, com: [0.1, -0.05, 0.2], inertia: [80, 90, 70, 1, 2, 3]}
  - name: arm
    parent: bus
    joint: {type: revolute, axis: [0, 1, 0], position: [0.5, 0.0, 0.3]}
    mass: 20.0
    com: [1.0, 0.0, 0.0]
    inertia: [0.5, 6.0, 6.0, 0, 0, 0]
initial:
  q: {arm.angle: 0.3}
  u: {arm.angle_rate: 0.01}
  orbit: )" + orbit_keys + "\n" + kSensors;
}

VecX outputs(Engine& e, double t, const VecX& q, const VecX& u) {
  VecX y;
  e.outputs(t, q, u, VecX::Zero(e.model().nu), y);
  return y;
}

std::vector<Engine*> both(GenericEngine& g, std::unique_ptr<GeneratedEngine>& gen) { return {&g, gen.get()}; }

/// A run of `orbits` orbits of period T with rkf78 at rtol (atol in m and m/s), `per_orbit` rows each.
RowTable run_orbits(Engine& e, const Model& model, double T, int orbits, int per_orbit, double rtol, double atol) {
  SimulationOptions o;
  o.t_end = orbits * T;
  o.dt_out = T / per_orbit;
  o.integrator.kind = IntegratorKind::rkf78;
  o.integrator.rtol = rtol;
  o.integrator.atol = atol;
  RowTable rows;
  simulate(e, initial_state(model), o, rows);
  return rows;
}

}  // namespace

TEST_CASE("orbit-frame sensors read back the initial orbit, the centre of mass and the LVLH offsets, both engines",
          "[central][outputs]") {
  const OrbitElements el{7.2e6, 0.1, 0.5, 0.3, 0.8, 0.4};
  const OrbitState target = state_from_elements(kMu, el);
  const Eigen::Quaterniond Q_LB = Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2).normalized();
  const Vec3 rate(1.0e-3, -2.0e-3, 5.0e-4);
  const Model model = load_model(test::write_temp(
      "orbit_sensors.yaml",
      orbiter(fmt::format("{{a: 7.2e6, e: 0.1, i: 0.5, raan: 0.3, argp: 0.8, nu: 0.4, attitude: lvlh, attitude_offset: "
                          "{{quaternion: [{:.17g}, {:.17g}, {:.17g}, {:.17g}]}}, rate_offset: [1.0e-3, -2.0e-3, 5.0e-4]}}",
                          Q_LB.w(), Q_LB.x(), Q_LB.y(), Q_LB.z()))));
  REQUIRE(model.ny == 7 + 3 + 3 + 3 + 6);
  GenericEngine generic(model);
  auto generated = test::generated_engine(model);
  const State s = initial_state(model);
  const Eigen::AngleAxisd aa(Q_LB);
  const Vec3 rv = aa.angle() * aa.axis();
  for (Engine* e : both(generic, generated)) {
    INFO(e->name());
    const VecX y = outputs(*e, 0.0, s.q, s.u);
    auto at = [&](const std::string& n) { return y(model.output_index(n)); };
    CHECK((Vec3(at("com.x"), at("com.y"), at("com.z")) - target.r_N).norm() <= 1e-12 * target.r_N.norm());
    CHECK((Vec3(at("comv.x"), at("comv.y"), at("comv.z")) - target.v_N).norm() <= 1e-12 * target.v_N.norm());
    CHECK(std::abs(at("osc.a") - el.a) <= 1e-9 * el.a);
    CHECK(std::abs(at("osc.e") - el.e) <= 1e-12);
    for (const auto& [n, v] : std::vector<std::pair<std::string, double>>{
             {"osc.i", el.i}, {"osc.raan", el.raan}, {"osc.argp", el.argp}, {"osc.nu", el.nu}})
      CHECK(std::abs(at(n) - v) <= 1e-11);
    const Eigen::Vector4d q_LB(at("att.qw"), at("att.qx"), at("att.qy"), at("att.qz"));
    CHECK((q_LB - Eigen::Vector4d(Q_LB.w(), Q_LB.x(), Q_LB.y(), Q_LB.z())).norm() <= 1e-12);
    CHECK((Vec3(at("att.roll"), at("att.pitch"), at("att.yaw")) - rv).norm() <= 1e-12);
    CHECK((Vec3(at("rate.x"), at("rate.y"), at("rate.z")) - rate).norm() <= 1e-15);
  }
  // a pitch offset alone reads as pitch, exactly (the rotation vector, not 2 q)
  const Model pitched = load_model(test::write_temp(
      "orbit_sensors_pitch.yaml",
      orbiter("{a: 6.978e6, e: 0.001, i: 1.7, raan: 0.3, argp: 0.0, nu: 0.0, attitude: lvlh, "
              "attitude_offset: {rpy: [0.0, 0.3, 0.0]}}")));
  GenericEngine g2(pitched);
  const State s2 = initial_state(pitched);
  const VecX y2 = outputs(g2, 0.0, s2.q, s2.u);
  CHECK(std::abs(y2(pitched.output_index("att.pitch")) - 0.3) <= 1e-15);
  CHECK(std::abs(y2(pitched.output_index("att.roll"))) <= 1e-15);
  CHECK(std::abs(y2(pitched.output_index("att.yaw"))) <= 1e-15);
}

TEST_CASE("orbit-frame sensors along the motion: the attitude relative to LVLH turns at the relative rate, both engines",
          "[central][outputs][physics]") {
  const Model model = load_model(test::write_temp(
      "orbit_sensors_motion.yaml",
      orbiter("{a: 7.2e6, e: 0.1, i: 0.5, raan: 0.3, argp: 0.8, nu: 0.4, attitude: lvlh, "
              "attitude_offset: {rpy: [0.1, -0.2, 0.3]}, rate_offset: [1.0e-3, -2.0e-3, 5.0e-4]}")));
  GenericEngine generic(model);
  auto generated = test::generated_engine(model);
  const State s = initial_state(model);
  for (Engine* e : both(generic, generated)) {
    INFO(e->name());
    VecX qd, ud;
    e->qdot(s.q, s.u, qd);
    e->udot(s.q, s.u, VecX::Zero(model.nu), ud);
    const double h = 1e-2;  // s: the orbit's scale is 1e3 s, the relative motion's 1e3 s
    const VecX yp = outputs(*e, 0, s.q + h * qd, s.u + h * ud), ym = outputs(*e, 0, s.q - h * qd, s.u - h * ud);
    const VecX y = outputs(*e, 0, s.q, s.u), dy = (yp - ym) / (2 * h);
    auto seg = [&](const VecX& v, const std::string& n, int k) { return VecX(v.segment(model.output_index(n), k)); };
    const Eigen::Vector4d a = seg(y, "att.qw", 4), da = seg(dy, "att.qw", 4);
    const Eigen::Quaterniond Q(a(0), a(1), a(2), a(3)), dQ(da(0), da(1), da(2), da(3));
    const Eigen::Quaterniond W = Q.conjugate() * dQ;  // [0; w_rel_B / 2]
    const Vec3 w_rel = seg(y, "rate.x", 3);
    CHECK(std::abs(W.w()) <= 1e-9);
    CHECK((2.0 * W.vec() - w_rel).norm() <= 1e-7 * w_rel.norm());
    // the centre of mass's velocity is the derivative of its position
    const Vec3 dr = seg(dy, "com.x", 3), v = seg(y, "comv.x", 3);
    CHECK((dr - v).norm() <= 1e-9 * v.norm());
  }
}

TEST_CASE("orbit-frame sensors on a Kepler orbit: the osculating elements stay and nu follows Kepler over 10 orbits, "
          "both engines",
          "[central][outputs]") {
  const OrbitElements el{7.2e6, 0.1, 0.5, 0.3, 0.8, 0.4};
  // isotropic inertia: the attitude does not couple into the orbit
  const Model model = load_model(test::write_temp("kepler_sensors.yaml", R"(name: kepler_sensors
gravity: {central: {mu: 3.986004418e14}}
bodies:
  - {name: sat, parent: ground, joint: {type: free}, mass: 100.0, inertia: [10.0, 10.0, 10.0, 0, 0, 0]}
initial:
  orbit: {a: 7.2e6, e: 0.1, i: 0.5, raan: 0.3, argp: 0.8, nu: 0.4}
outputs:
  - {name: osc, type: orbit_elements}
)"));
  GenericEngine generic(model);
  auto generated = test::generated_engine(model);
  const double T = orbital_period(kMu, el.a);
  for (Engine* e : both(generic, generated)) {
    INFO(e->name());
    const RowTable rows = run_orbits(*e, model, T, 10, 20, 1e-13, 1e-6);  // atol: 1e-13 of 7e6 m
    const auto t = rows.column("t");
    double worst_a = 0, worst_e = 0, worst_angle = 0, worst_nu = 0;
    for (std::size_t k = 0; k < t.size(); ++k) {
      worst_a = std::max(worst_a, std::abs(rows.column("osc.a")[k] - el.a) / el.a);
      worst_e = std::max(worst_e, std::abs(rows.column("osc.e")[k] - el.e));
      for (const auto& [n, v] : std::vector<std::pair<std::string, double>>{
               {"osc.i", el.i}, {"osc.raan", el.raan}, {"osc.argp", el.argp}})
        worst_angle = std::max(worst_angle, std::abs(rows.column(n)[k] - v));
      const double nu = true_anomaly_at(kMu, el, t[k]);
      worst_nu = std::max(worst_nu, std::abs(std::remainder(rows.column("osc.nu")[k] - nu, 2 * M_PI)));
    }
    INFO("10 orbits, e = 0.1: a " << worst_a << " relative, e " << worst_e << ", i/raan/argp " << worst_angle
                                  << " rad, nu against Kepler " << worst_nu << " rad");
    CHECK(worst_a <= 1e-9);
    CHECK(worst_e <= 1e-9);
    CHECK(worst_angle <= 1e-9);
    CHECK(worst_nu <= 1e-8);
  }
}

TEST_CASE("J2 nodal regression: the node turns at -3/2 n J2 (R/p)^2 cos i within 1 % over 20 orbits, both engines",
          "[central][outputs]") {
  // e = 0.05, i = 0.9 rad at 7,000 km; the secular rate from the initial
  // (osculating) a, e, i; the run's rate is the least-squares slope of the
  // osculating raan over 20 whole orbits, which averages its short-period terms
  const OrbitElements el{7.0e6, 0.05, 0.9, 0.3, 0.8, 0.4};
  const double J2 = 1.08262668e-3, R = 6378137.0;
  const Model model = load_model(test::write_temp("j2_node.yaml", R"(name: j2_node
gravity: {central: {mu: 3.986004418e14, J2: 1.08262668e-3, radius: 6378137.0}}
bodies:
  - {name: sat, parent: ground, joint: {type: free}, mass: 100.0, inertia: [10.0, 10.0, 10.0, 0, 0, 0]}
initial:
  orbit: {a: 7.0e6, e: 0.05, i: 0.9, raan: 0.3, argp: 0.8, nu: 0.4}
outputs:
  - {name: osc, type: orbit_elements}
)"));
  const double n = std::sqrt(kMu / (el.a * el.a * el.a));
  const double p = el.a * (1 - el.e * el.e);
  const double raan_rate = -1.5 * n * J2 * (R / p) * (R / p) * std::cos(el.i);
  GenericEngine generic(model);
  auto generated = test::generated_engine(model);
  const double T = orbital_period(kMu, el.a);
  for (Engine* e : both(generic, generated)) {
    INFO(e->name());
    const RowTable rows = run_orbits(*e, model, T, 20, 50, 1e-12, 1e-5);
    const auto t = rows.column("t");
    const auto raan = rows.column("osc.raan");
    const double N = static_cast<double>(t.size());
    double st = 0, sy = 0, stt = 0, sty = 0;
    for (std::size_t k = 0; k < t.size(); ++k) {
      st += t[k];
      sy += raan[k];
      stt += t[k] * t[k];
      sty += t[k] * raan[k];
    }
    const double slope = (N * sty - st * sy) / (N * stt - st * st);
    INFO("raan rate " << slope << " rad/s against " << raan_rate << " (" << slope * 86400 * 180 / M_PI
                      << " deg/day against " << raan_rate * 86400 * 180 / M_PI << "), relative error "
                      << (slope - raan_rate) / std::abs(raan_rate) << "; drift over 20 orbits " << raan.back() - raan.front()
                      << " rad");
    CHECK(std::abs(slope - raan_rate) <= 0.01 * std::abs(raan_rate));
  }
}

TEST_CASE("orbit-frame sensors: refused without a central field or with a body on a system sensor, with line and "
          "field",
          "[central][outputs]") {
  const std::string head = R"(name: bad_sensors
bodies:
  - {name: bus, parent: ground, joint: {type: free}, mass: 200.0, inertia: [80, 90, 70, 0, 0, 0]}
outputs:
)";
  CHECK_THROWS_WITH(load_model(test::write_temp("bad_sensors.yaml", head + "  - {name: att, type: attitude_lvlh, body: bus}\n")),
                    Catch::Contains(":5: outputs[0].type: 'attitude_lvlh' is relative to the central body"));
  CHECK_THROWS_WITH(load_model(test::write_temp("bad_sensors.yaml", head + "  - {name: osc, type: orbit_elements}\n")),
                    Catch::Contains("outputs[0].type: 'orbit_elements' is relative to the central body"));
  CHECK_THROWS_WITH(
      load_model(test::write_temp("bad_sensors.yaml", "gravity: {central: {mu: 3.986004418e14}}\n" + head +
                                                          "  - {name: c, type: com_position, body: bus}\n")),
      Catch::Contains("outputs[0]"));
}

namespace {

/// The frequencies (rad/s) of a signal sampled every dt that is a sum of
/// `pairs` undamped sinusoids: Prony's linear prediction of order 2 pairs fitted
/// by least squares over every signal given, its characteristic roots
/// exp(+-i w dt) from the companion matrix. Independent of any model.
std::vector<double> prony_frequencies(const std::vector<std::vector<double>>& signals, double dt, int pairs) {
  const int p = 2 * pairs;
  std::vector<Eigen::VectorXd> rows;
  std::vector<double> rhs;
  for (const auto& x : signals)
    for (std::size_t k = p; k < x.size(); ++k) {
      Eigen::VectorXd r(p);
      for (int j = 0; j < p; ++j) r(j) = x[k - 1 - j];
      rows.push_back(r);
      rhs.push_back(x[k]);
    }
  Eigen::MatrixXd A(rows.size(), p);
  Eigen::VectorXd b(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) A.row(i) = rows[i].transpose(), b(i) = rhs[i];
  const Eigen::VectorXd a = A.colPivHouseholderQr().solve(b);
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(p, p);  // z^p = a1 z^(p-1) + ... + ap
  C.row(0) = a.transpose();
  for (int j = 1; j < p; ++j) C(j, j - 1) = 1.0;
  std::vector<double> w;
  const Eigen::EigenSolver<Eigen::MatrixXd> roots(C);
  for (const auto& z : roots.eigenvalues())
    if (z.imag() > 0) w.push_back(std::arg(z) / dt);
  std::sort(w.begin(), w.end());
  return w;
}

}  // namespace

TEST_CASE("librations in a circular orbit: pitch at n sqrt(3 (Ix - Iz)/Iy) and the roll-yaw pair at the roots of "
          "Hughes' characteristic equation, from runs in both engines",
          "[central][outputs][physics]") {
  // principal axes along L's: x along track (roll), y against the orbit normal (pitch), z to nadir (yaw);
  // Iy > Ix > Iz: inside the Lagrange region (gravity-gradient stable)
  const double Ix = 400.0, Iy = 500.0, Iz = 150.0, a = 6.978137e6;
  const Model model = load_model(test::write_temp("libration.yaml", fmt::format(R"(name: libration
gravity: {{central: {{mu: 3.986004418e14}}}}
bodies:
  - {{name: bus, parent: ground, joint: {{type: free}}, mass: 500.0, inertia: [{}, {}, {}, 0, 0, 0]}}
initial:
  orbit: {{a: {}, e: 0.0, i: 0.9, raan: 0.3, argp: 0.0, nu: 0.0, attitude: lvlh,
          attitude_offset: {{rpy: [1.0e-6, -1.0e-6, 2.0e-6]}}, rate_offset: [1.0e-9, 0.0, -2.0e-9]}}
outputs:
  - {{name: att, type: attitude_lvlh, body: bus}}
)",
                                                                                  Ix, Iy, Iz, a)));
  const double n = std::sqrt(kMu / (a * a * a));
  const test::Librations lib = test::rigid_librations(Ix, Iy, Iz, n);
  const double pitch = lib.pitch, slow = lib.roll_yaw_slow, fast = lib.roll_yaw_fast;
  GenericEngine generic(model);
  auto generated = test::generated_engine(model);
  for (Engine* e : both(generic, generated)) {
    INFO(e->name());
    SimulationOptions o;
    const double T = 2.0 * M_PI / n;
    o.t_end = 4.0 * T;
    o.dt_out = T / 200.0;
    o.integrator.kind = IntegratorKind::rkf78;
    o.integrator.rtol = 1e-13;
    // amplitudes of 1e-6 rad (their products, the nonlinear coupling, 1e-12) need an absolute tolerance far
    // below them on the quaternion and rates: rtol alone keeps the orbit's 7e6 m to 1e-6 m
    o.integrator.atol = 1e-16;
    RowTable rows;
    simulate(*e, initial_state(model), o, rows);
    const auto t = rows.column("t");
    auto uniform = [&](const std::string& name) {  // the rows on the dt_out grid (a last row at t_end may be closer)
      std::vector<double> x;
      const auto c = rows.column(name);
      for (std::size_t k = 0; k < t.size(); ++k)
        if (std::abs(t[k] - static_cast<double>(x.size()) * o.dt_out) <= 1e-6 * o.dt_out) x.push_back(c[k]);
      return x;
    };
    const auto w_pitch = prony_frequencies({uniform("att.pitch")}, o.dt_out, 1);
    const auto w_ry = prony_frequencies({uniform("att.roll"), uniform("att.yaw")}, o.dt_out, 2);
    REQUIRE(w_pitch.size() == 1);
    REQUIRE(w_ry.size() == 2);
    INFO(std::setprecision(9) << "pitch " << w_pitch[0] / n << " n against " << pitch / n << " n; roll-yaw " << w_ry[0] / n << ", "
                  << w_ry[1] / n << " n against " << slow / n << ", " << fast / n << " n");
    CHECK(std::abs(w_pitch[0] - pitch) <= 2e-6 * pitch);
    CHECK(std::abs(w_ry[0] - slow) <= 2e-6 * slow);
    CHECK(std::abs(w_ry[1] - fast) <= 2e-6 * fast);
  }
}
