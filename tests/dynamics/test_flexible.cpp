// Flexible bodies along simulated motion (generic engine + integrators):
// invariants of undamped / free-floating flexible models, the clamped beam's
// vibration frequency against its modal data, and the rigid limit of a stiff
// appendage. (Beam frequencies against Euler-Bernoulli at 40 elements and the
// modal-file round trip are in test_modal_data.cpp.)
#include <catch2/catch.hpp>
#include <fstream>
#include <sstream>
#include <cmath>
#include <string>
#include <vector>

#include "model/beam.hpp"
#include "engine/generic_engine.hpp"
#include "sim/integrators.hpp"
#include "engine/load_model.hpp"
#include "sim/simulate.hpp"
#include "model/state_io.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

VecX initial_x(const Model& model, const State& s0) {
  VecX x0(model.nq + model.nu);
  x0 << s0.q, s0.u;
  return x0;
}

// A flexible arm (revolute to ground, sprung) in a skew gravity field, with a
// rigid child on a revolute joint at the arm's tip node; no damping anywhere.
const char* kFlexPendulum = R"(
name: flex_pendulum_undamped
gravity: [0.3, -0.5, -9.81]
bodies:
  - name: arm
    parent: ground
    joint: {type: revolute, axis: [0, 1, 0], stiffness: 2.0, rest: 0.1}
    mass: 0.4
    com: [0.05, 0, 0.01]
    inertia: [0.001, 0.002, 0.002, 0, 0, 0]
    flexible:
      beam: {length: 1.0, direction: x, mass_per_length: 0.6, EI: [30.0, 45.0], elements: 8, modes: 3}
      damping_ratio: 0.0
  - name: tip
    parent: arm
    joint: {type: revolute, axis: [0, 0, 1], node: 9, rotation: {rpy: [0.2, 0, 0.3]}}
    mass: 0.2
    com: [0.1, 0.02, 0]
    inertia: [0.0005, 0.001, 0.001, 0, 0, 0.0001]
initial:
  q: {arm.angle: 0.6, arm.eta1: 0.02, arm.eta2: -0.01, tip.angle: 0.4}
  u: {arm.angle: 0.5, tip.angle: -1.0, arm.eta3: 0.1}
outputs: [energy]
)";

/// A free bus with one flexible beam appendage on a fixed joint; EI scales
/// both bending stiffnesses.
std::string stiff_appendage_yaml(double EI) {
  return R"(
name: stiff_appendage
bodies:
  - name: bus
    parent: ground
    joint: {type: free}
    mass: 50.0
    com: [0.01, 0.02, -0.01]
    inertia: [4.0, 5.0, 3.0, 0.1, -0.05, 0.02]
  - name: app
    parent: bus
    joint: {type: fixed, position: [0.5, 0.1, 0.0], rotation: {rpy: [0.1, 0.2, 0.3]}}
    flexible:
      beam: {length: 2.0, direction: x, mass_per_length: 2.0, EI: [)" +
         std::to_string(EI) + ", " + std::to_string(1.3 * EI) + R"(], elements: 10, modes: 2}
      damping_ratio: 0.0
initial:
  q: {bus.qw: 0.9, bus.qx: 0.3, bus.qy: -0.1, bus.qz: 0.3}
  u: {bus.vx: 0.1, bus.wx: 0.3, bus.wy: -0.2, bus.wz: 0.5}
)";
}

/// The same system with the appendage rigid: a rigid part whose mass, com and
/// inertia about the com are those of the flexible body's lumped nodes.
Model rigid_equivalent(const Model& flex_model, const std::string& body) {
  Model m = flex_model;
  Body& b = m.bodies[m.body_index(body)];
  REQUIRE(b.flex);
  const FlexibleData& fd = *b.flex;
  double mass = b.rigid.mass;
  Vec3 first = b.rigid.mass * b.rigid.com_B;
  for (const ModalNode& n : fd.nodes) {
    mass += n.mass;
    first += n.mass * n.rho_B;
  }
  const Vec3 com = first / mass;
  auto point_inertia = [](double mk, const Vec3& r) {
    return Mat3(mk * (r.squaredNorm() * Mat3::Identity() - r * r.transpose()));
  };
  Mat3 I = b.rigid.I_c_B + point_inertia(b.rigid.mass, b.rigid.com_B - com);
  for (const ModalNode& n : fd.nodes) I += n.J_B + point_inertia(n.mass, n.rho_B - com);
  b.flex.reset();
  b.rigid.mass = mass;
  b.rigid.com_B = com;
  b.rigid.I_c_B = I;
  // initial state by name (the modal coordinates disappear)
  const VecX q0 = flex_model.q0, u0 = flex_model.u0;
  m.q0.resize(0);
  m.u0.resize(0);
  finalize_model(m);
  for (int i = 0; i < m.nq; ++i) m.q0(i) = q0(flex_model.q_index(m.q_names[i]));
  for (int i = 0; i < m.nu; ++i) m.u0(i) = u0(flex_model.u_index(m.u_names[i]));
  return m;
}

/// Bus angular velocity (body axes) at the output times 0, dt, ..., t_end.
std::vector<Vec3> bus_rates(const Model& model, double t_end, double dt) {
  GenericEngine engine(model);
  const State s0 = initial_state(model);
  OdeProblem ode = make_ode_problem(engine, s0.tau, nullptr);
  IntegratorOptions opt;
  opt.kind = IntegratorKind::cvode_bdf;  // stiff for the large EI
  opt.rtol = 1e-11;
  opt.atol = 1e-13;
  const int iw = model.u_index("bus.wx");
  std::vector<Vec3> w;
  integrate(ode, opt, 0.0, initial_x(model, s0), t_end, dt, [&](double, const VecX& x) {
    w.push_back(x.segment<3>(model.nq + iw));
    return true;
  });
  return w;
}

}  // namespace

TEST_CASE("flexible: energy is conserved on an undamped flexible arm with gravity and a child at a node",
          "[flexible][conservation][generic]") {
  const Model model = load_model(test::write_temp("flex_pendulum_undamped.yaml", kFlexPendulum));
  REQUIRE(model.bodies[0].flex);
  REQUIRE(model.bodies[1].joint.node == 8);  // node id 9 = the tip, index 8
  const test::Drift d = test::run_invariants(model, 5.0, IntegratorKind::cvode_bdf, 1e-12, 100);
  INFO("energy drift " << d.energy);
  CHECK(d.energy < 1e-9);
}

TEST_CASE("flexible: momenta are conserved on the free-floating spacecraft_arrays model",
          "[flexible][conservation][generic]") {
  // Modal and joint damping are internal: p and H stay constant, T + V falls.
  const Model model = load_model(test::source_path("models/spacecraft_arrays.yaml"));
  REQUIRE(model.has_flexible());
  const test::Drift d = test::run_invariants(model, 20.0, IntegratorKind::cvode_adams, 1e-11, 100);
  INFO("p drift " << d.p << ", H drift " << d.H);
  CHECK(d.p < 1e-9);
  CHECK(d.H < 1e-9);
}

TEST_CASE("flexible: the clamped beam vibrates at its first modal frequency", "[flexible][closed-form][generic]") {
  const Model model = load_model(test::source_path("models/clamped_beam.yaml"));
  REQUIRE(model.nu == 4);
  const FlexibleData& fd = *model.bodies[0].flex;
  const double f1 = fd.frequency_hz(0);

  // the 20-element beam against Euler-Bernoulli (EI about y = 20, mu = 0.5, L = 1)
  const double f_eb = 1.875104 * 1.875104 * std::sqrt(20.0 / (0.5 * 1.0)) / (2 * M_PI);
  INFO("beam f1 " << f1 << " Hz, Euler-Bernoulli " << f_eb << " Hz");
  CHECK(std::abs(f1 / f_eb - 1) < 0.01);

  // free vibration from eta1(0) = 0.01: zero crossings of eta1 over ~20 periods
  GenericEngine engine(model);
  const State s0 = initial_state(model);
  REQUIRE(s0.q(0) == 0.01);
  OdeProblem ode = make_ode_problem(engine, s0.tau, nullptr);
  IntegratorOptions opt;
  opt.kind = IntegratorKind::arkode_erk;
  opt.rtol = 1e-11;
  opt.atol = 1e-14;
  std::vector<double> crossings;
  double t_prev = 0, e_prev = s0.q(0), other = 0;
  integrate(ode, opt, 0.0, initial_x(model, s0), 6.0, 1e-3, [&](double t, const VecX& x) {
    const double e = x(0);
    if (t > 0 && (e_prev > 0) != (e > 0)) crossings.push_back(t_prev + e_prev * (t - t_prev) / (e_prev - e));
    t_prev = t;
    e_prev = e;
    other = std::max(other, x.segment(1, 3).cwiseAbs().maxCoeff());
    return true;
  });
  REQUIRE(crossings.size() >= 40);
  const double f_meas = (crossings.size() - 1) / (2.0 * (crossings.back() - crossings.front()));
  INFO(crossings.size() << " zero crossings: " << f_meas << " Hz, modal data " << f1 << " Hz");
  CHECK(std::abs(f_meas / f1 - 1) < 1e-4);
  INFO("largest |eta2..4| " << other);
  CHECK(other < 1e-12);  // the modes are mass-orthogonal: no coupling with a fixed base
}

TEST_CASE("flexible: with foreshortening the clamped beam softens with amplitude squared", "[flexible][generic]") {
  // The node's axial motion 1/2 gamma(eta) adds kinetic energy ~ eta^2 eta_dot^2:
  // the free vibration's frequency falls by a relative amount proportional to
  // the amplitude squared (an inertial nonlinearity; energy stays exact).
  const std::string yaml = [] {
    std::ifstream in(test::source_path("models/clamped_beam.yaml"));
    std::stringstream ss;
    ss << in.rdbuf();
    std::string t = ss.str();
    t.replace(t.find("foreshortening: false"), 21, "foreshortening: true ");
    return t;
  }();
  const Model model = load_model(test::write_temp("clamped_beam_fs.yaml", yaml));
  REQUIRE(model.bodies[0].flex->has_second_order(20));
  const double f1 = model.bodies[0].flex->frequency_hz(0);
  auto measured = [&](double amplitude) {
    GenericEngine engine(model);
    State s0 = initial_state(model);
    s0.q(0) = amplitude;
    OdeProblem ode = make_ode_problem(engine, s0.tau, nullptr);
    IntegratorOptions opt;
    opt.kind = IntegratorKind::arkode_erk;
    opt.rtol = 1e-12;
    opt.atol = 1e-15;
    std::vector<double> crossings;
    double t_prev = 0, e_prev = s0.q(0);
    integrate(ode, opt, 0.0, initial_x(model, s0), 6.0, 1e-4, [&](double t, const VecX& x) {
      if (t > 0 && (e_prev > 0) != (x(0) > 0)) crossings.push_back(t_prev + e_prev * (t - t_prev) / (e_prev - x(0)));
      t_prev = t, e_prev = x(0);
      return true;
    });
    return (crossings.size() - 1) / (2.0 * (crossings.back() - crossings.front()));
  };
  const double d1 = measured(0.01) / f1 - 1, d2 = measured(0.02) / f1 - 1;
  INFO("frequency shift at eta1 = 0.01: " << d1 << ", at 0.02: " << d2);
  CHECK(d1 < -1e-5);                   // softening, clearly above the 1e-7 resolution here
  CHECK(d2 / d1 == Approx(4.0).epsilon(0.05));  // ~ amplitude squared
}

TEST_CASE("flexible: a stiff appendage tends to the rigid one", "[flexible][generic]") {
  // Same mass distribution, same state (eta = eta_dot = 0). At t = 0 the two
  // u-dots differ by an EI-independent amount (the modes are free to take up
  // acceleration: inertia coupling), but that only lasts a fraction of a
  // vibration period. Over a finite time the bus rate of the flexible model
  // differs from the rigid one by the undamped vibration the initial loads
  // start (its momentum ~ load / omega0 ~ EI^-1/2) plus the quasi-static
  // deflection (~ EI^-1). So the largest bus-rate difference over 1 s must
  // fall monotonically, by about sqrt(100) = 10 per factor 100 in EI (the
  // vibration dominates: no damping).
  const Model rigid = rigid_equivalent(load_model(test::write_temp("stiff_app.yaml", stiff_appendage_yaml(1e2))), "app");
  REQUIRE(rigid.nu == 6);
  const double t_end = 1.0, dt = 1e-3;
  const std::vector<Vec3> w_rigid = bus_rates(rigid, t_end, dt);
  double w_scale = 0;
  for (const Vec3& w : w_rigid) w_scale = std::max(w_scale, w.norm());

  std::vector<double> err;
  std::string report;
  for (double EI : {1e2, 1e4, 1e6, 1e8}) {
    const Model flex = load_model(test::write_temp("stiff_app.yaml", stiff_appendage_yaml(EI)));
    REQUIRE(flex.nu == 8);
    // the rigid model's mass data are the flexible body's, whatever EI
    const Model r = rigid_equivalent(flex, "app");
    CHECK(r.bodies[1].rigid.I_c_B == rigid.bodies[1].rigid.I_c_B);
    const std::vector<Vec3> w_flex = bus_rates(flex, t_end, dt);
    REQUIRE(w_flex.size() == w_rigid.size());
    double e = 0;
    for (std::size_t k = 0; k < w_flex.size(); ++k) e = std::max(e, (w_flex[k] - w_rigid[k]).norm());
    err.push_back(e / w_scale);
    report += "EI " + std::to_string(EI) + " (f1 " + std::to_string(flex.bodies[1].flex->frequency_hz(0)) +
              " Hz): " + std::to_string(err.back()) + "\n";
  }
  INFO("largest relative bus-rate difference over 1 s:\n" << report);
  // measured: 3.2e-3, 3.3e-4, 3.2e-5, 3.2e-6
  for (std::size_t k = 1; k < err.size(); ++k) {
    CHECK(err[k] < err[k - 1]);
    CHECK(err[k - 1] / err[k] > 6);   // the EI^-1/2 law: 10 per factor 100
    CHECK(err[k - 1] / err[k] < 16);
  }
  CHECK(err.back() < 1e-3);
}
