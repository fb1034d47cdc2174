// Invariants along simulated motion (generic engine + integrators): energy of
// undamped systems, linear and angular momentum of free-floating ones, and
// the exact solution of a torque-free axisymmetric body.
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/generic_engine.hpp"
#include "sim/integrators.hpp"
#include "engine/load_model.hpp"
#include "sim/simulate.hpp"
#include "model/state_io.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

const char* kDoublePendulum3D = R"(
name: dp3d_undamped
gravity: [0.5, -1.0, -9.81]
bodies:
  - name: a
    parent: ground
    joint: {type: revolute, axis: [0, 1, 0], stiffness: 3.0, rest: 0.1}
    mass: 1.2
    com: [0.4, 0.05, 0]
    inertia: [0.01, 0.06, 0.055, 0.001, -0.002, 0.0005]
  - name: b
    parent: a
    joint: {type: revolute, axis: [0.6, 0, 0.8], position: [0.8, 0, 0], rotation: {rpy: [0.2, -0.3, 0.4]}}
    mass: 0.7
    com: [0.3, 0, 0.02]
    inertia: [0.005, 0.03, 0.03, 0, 0, 0.001]
  - name: c
    parent: b
    joint: {type: prismatic, axis: [1, 0, 0], position: [0.6, 0, 0], stiffness: 40.0, rest: 0.05}
    mass: 0.3
    com: [0.05, 0, 0]
    inertia: [0.001, 0.002, 0.002, 0, 0, 0]
initial:
  q: {a.angle: 0.7, b.angle: -0.4, c.disp: 0.1}
  u: {a.angle: 1.0, b.angle: 2.0, c.disp: -0.3}
outputs: [energy]
)";

const char* kFreeAppendages = R"(
name: free_undamped
bodies:
  - name: bus
    parent: ground
    joint: {type: free}
    mass: 20.0
    com: [0.02, -0.01, 0.05]
    inertia: [2.0, 2.5, 1.5, 0.05, -0.02, 0.01]
  - name: arm1
    parent: bus
    joint: {type: revolute, axis: [0, 0, 1], position: [0.5, 0, 0], stiffness: 5.0}
    mass: 1.0
    com: [0.4, 0, 0]
    inertia: [0.001, 0.05, 0.05, 0, 0, 0]
  - name: arm2
    parent: bus
    joint: {type: revolute, axis: [0, 1, 0], position: [-0.5, 0, 0.1], rotation: {rpy: [0, 0, 3.14159]}}
    mass: 0.8
    com: [0.3, 0.02, 0]
    inertia: [0.001, 0.03, 0.03, 0, 0, 0]
  - name: pod
    parent: arm1
    joint: {type: free, position: [0.8, 0, 0]}
    mass: 0.5
    com: [0.01, 0, 0]
    inertia: [0.002, 0.003, 0.004, 0, 0, 0]
initial:
  q: {bus.qw: 0.9, bus.qx: 0.1, bus.qy: 0.3, bus.qz: 0.3, arm1.angle: 0.3}
  u: {bus.vx: 0.1, bus.vy: -0.2, bus.wx: 0.3, bus.wy: -0.5, bus.wz: 1.0, arm1.angle: -0.5, arm2.angle: 0.8,
      pod.vx: 0.05, pod.wz: 0.7}
outputs: [energy, momentum]
)";

}  // namespace

TEST_CASE("energy is conserved on an undamped 3D chain with gravity and springs", "[conservation][generic]") {
  const Model model = load_model(test::write_temp("dp3d_undamped.yaml", kDoublePendulum3D));
  const test::Drift d = test::run_invariants(model, 10.0, IntegratorKind::cvode_bdf, 1e-12);
  INFO("energy drift " << d.energy);
  CHECK(d.energy < 1e-9);
}

TEST_CASE("energy and momenta are conserved on a free-floating tree", "[conservation][generic]") {
  std::string text = kFreeAppendages;
  const Model model = load_model(test::write_temp("free_undamped.yaml", text));
  for (IntegratorKind kind : {IntegratorKind::cvode_bdf, IntegratorKind::arkode_erk}) {
    const test::Drift d = test::run_invariants(model, 10.0, kind, 1e-12);
    INFO(to_string(kind) << ": energy " << d.energy << ", p " << d.p << ", H " << d.H);
    CHECK(d.energy < 1e-9);
    CHECK(d.p < 1e-9);
    CHECK(d.H < 1e-9);
  }
}

TEST_CASE("torque-free axisymmetric body follows the exact solution", "[closed-form][conservation][generic]") {
  // I = diag(I1, I1, I3): w3 constant, (w1 + i w2)(t) = (w1 + i w2)(0) exp(i Omega t),
  // Omega = (I3 - I1) w3 / I1; H in N constant.
  const double I1 = 2.0, I3 = 0.5, w10 = 0.3, w20 = -0.2, w30 = 4.0;
  const std::string text = R"(
name: axisym
bodies:
  - name: b
    parent: ground
    joint: {type: free}
    mass: 3.0
    inertia: [2.0, 2.0, 0.5, 0, 0, 0]
initial:
  q: {b.qw: 0.8, b.qx: 0.6, b.qy: 0, b.qz: 0}
  u: {b.wx: 0.3, b.wy: -0.2, b.wz: 4.0, b.vx: 0.5}
)";
  const Model model = load_model(test::write_temp("axisym.yaml", text));
  GenericEngine engine(model);
  const State s0 = initial_state(model);
  OdeProblem ode = make_ode_problem(engine, s0.tau, nullptr);
  IntegratorOptions opt;
  opt.kind = IntegratorKind::arkode_erk;  // most accurate per step on this non-stiff case
  opt.rtol = 1e-12;
  opt.atol = 1e-14;
  VecX x0(model.nq + model.nu);
  x0 << s0.q, s0.u;
  const double Omega = (I3 - I1) * w30 / I1;
  double err_w = 0, err_H = 0;
  Vec3 H0 = engine.momentum(s0.q, s0.u).H_N;
  integrate(ode, opt, 0.0, x0, 20.0, 0.5, [&](double t, const VecX& x) {
    const Vec3 w = x.segment<3>(model.nq + 3);
    const double c = std::cos(Omega * t), s = std::sin(Omega * t);
    const Vec3 w_exact(w10 * c - w20 * s, w10 * s + w20 * c, w30);
    err_w = std::max(err_w, (w - w_exact).norm() / w_exact.norm());
    const Vec3 H = engine.momentum(x.head(model.nq), x.tail(model.nu)).H_N;
    err_H = std::max(err_H, (H - H0).norm() / H0.norm());
    return true;
  });
  INFO("angular velocity error " << err_w << ", H drift " << err_H);
  CHECK(err_w < 1e-8);
  CHECK(err_H < 1e-9);
}
