// Foreshortening, node rotary inertia and prescribed motion (dynamics.md, the
// 2026-11-29 changes of ../shared/spec/CHANGES.md) held to invariants and
// closed forms: an undamped free flexible spacecraft with all three conserves
// E, p and H; a prescribed-motion scene's energy changes by exactly the work of
// its drivers; the built-in beam's torsion frequencies and foreshortening
// against the continuous Euler–Bernoulli / Saint-Venant beam; an exported
// beam behaves as the built-in one; the CSV shows the prescribed coordinates.
#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "engine/generic_engine.hpp"
#include "model/beam.hpp"
#include "model/modal_data.hpp"
#include "model/second_order.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "sim/integrators.hpp"
#include "sim/simulate.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

/// A free bus carrying a flexible beam (the v_spinup FE beam: node rotary
/// inertias, a pure torsion mode, second_order data) with a revolute tip body
/// at the beam's tip node; no gravity, no damping, no input.
std::string free_flexible_model(bool foreshortening) {
  return fmt::format(R"(
name: free_flexible
bodies:
  - name: bus
    parent: ground
    joint: {{type: free}}
    mass: 30.0
    com: [0.02, -0.01, 0.03]
    inertia: [3.0, 2.5, 2.0, 0.05, -0.02, 0.01]
  - name: beam
    parent: bus
    joint: {{type: fixed, position: [0.4, 0, 0.1], rotation: {{rpy: [0.1, 0.2, 0.3]}}}}
    flexible: {{modal: spinup_beam.modal.yaml, damping_ratio: 0.0, foreshortening: {}}}
  - name: tip
    parent: beam
    joint: {{type: revolute, node: 5, axis: [0, 1, 0], stiffness: 0.5}}
    mass: 0.15
    com: [0.03, 0.0, 0.0]
    inertia: [0.0001, 0.0002, 0.00022, 0.0, 0.0, 0.0]
initial:
  q: {{beam.eta1: 0.05, beam.eta2: -0.03, beam.eta3: 0.02, beam.eta4: 0.01, tip.angle: 0.3}}
  u: {{bus.wx: 0.3, bus.wy: -0.4, bus.wz: 2.0, bus.vx: 0.1, beam.eta1: 0.5, beam.eta3: 0.8, tip.angle: -1.0}}
outputs: [energy, momentum]
)",
                     foreshortening ? "true" : "false");
}

/// Writes a model to a temporary file, its modal file named by absolute path.
std::string write_model(const std::string& name, std::string text) {
  const std::string modal = test::source_path("tests/data/good/spinup_beam.modal.yaml");
  const std::string key = "modal: spinup_beam.modal.yaml";
  for (std::size_t p = 0; (p = text.find(key, p)) != std::string::npos; p += modal.size())
    text.replace(p, key.size(), "modal: " + modal);
  return test::write_temp(name, text);
}

}  // namespace

TEST_CASE("undamped free flexible body with foreshortening, node inertia and a node child conserves E, p, H",
          "[flexible][invariants][generic]") {
  for (const bool fs : {true, false}) {
    INFO("foreshortening " << fs);
    const Model model = load_model(write_model("free_flexible.yaml", free_flexible_model(fs)));
    REQUIRE(model.bodies[1].flex->has_second_order(4) == fs);
    REQUIRE(!model.bodies[1].rich_nodes.empty());
    const test::Drift d = test::run_invariants(model, 4.0, IntegratorKind::arkode_erk, 1e-12, 80);
    INFO("drift E " << d.energy << ", p " << d.p << ", H " << d.H);
    CHECK(d.energy < test::kDriftFactor * 1e-12);
    CHECK(d.p < test::kDriftFactor * 1e-12);
    CHECK(d.H < test::kDriftFactor * 1e-12);
  }
}

TEST_CASE("prescribed motion: E(t) - E(0) equals the drivers' work", "[prescribed][invariants]") {
  // A hub spun up about z (prescribed), a flexible beam with foreshortening on
  // it and a spring-tip at its tip node, a cart on a sine-driven slider: no
  // damping, gravity on. E - Integral tau_d f_dot dt must stay constant,
  // tau_d the reaction along each prescribed axis.
  const std::string yaml = R"(
name: driven
gravity: [0, 0, -9.81]
bodies:
  - name: hub
    parent: ground
    joint: {type: revolute, axis: [0, 0, 1], motion: {spinup: {rate: 3.0, duration: 2.0, start: 0.1}}}
    mass: 2.0
    com: [0.02, 0, 0.01]
    inertia: [0.05, 0.06, 0.08, 0, 0, 0.001]
  - name: beam
    parent: hub
    joint: {type: fixed, position: [0.25, 0, 0], rotation: {rpy: [0.05, 0, 0]}}
    flexible: {modal: spinup_beam.modal.yaml, damping_ratio: 0.0}
  - name: tip
    parent: beam
    joint: {type: revolute, node: 5, axis: [0, 1, 0], stiffness: 0.5}
    mass: 0.15
    com: [0.03, 0.0, 0.0]
    inertia: [0.0001, 0.0002, 0.00022, 0.0, 0.0, 0.0]
  - name: cart
    parent: hub
    joint: {type: prismatic, axis: [0, 1, 0], position: [-0.2, 0, 0], motion: {sine: {amplitude: 0.05, frequency: 1.5}}}
    mass: 0.5
    com: [0, 0, 0.02]
    inertia: [0.001, 0.001, 0.001, 0, 0, 0]
outputs: [energy, reactions]
)";
  const Model model = load_model(write_model("driven.yaml", yaml));
  REQUIRE(model.prescribed_names == std::vector<std::string>{"hub.angle", "cart.disp"});
  GenericEngine engine(model);
  const State s0 = initial_state(model);
  OdeProblem ode = make_ode_problem(engine, s0.tau, nullptr);
  IntegratorOptions opt;
  opt.kind = IntegratorKind::arkode_erk;
  opt.rtol = 1e-12;
  opt.atol = 1e-14;
  VecX x0(model.nq + model.nu);
  x0 << s0.q, s0.u;
  // Driver power P = Sum tau_d f_dot, integrated by Simpson's rule on a fine output grid.
  std::vector<double> ts, Es, Ps;
  double scale = 0;
  std::vector<Reaction> R;
  VecX udot;
  integrate(ode, opt, 0.0, x0, 4.0, 1e-3, [&](double t, const VecX& x) {
    const VecX q = x.head(model.nq), u = x.tail(model.nu);
    const EnergyValues E = engine.energy(t, q, u);
    engine.udot(t, q, u, s0.tau, udot);
    engine.reactions(t, q, u, udot, R);
    double P = 0;
    for (std::size_t i = 0; i < model.bodies.size(); ++i) {
      const Joint& j = model.bodies[i].joint;
      if (!j.prescribed()) continue;
      const double tau_d = (j.type == JointType::revolute ? R[i].torque_B : R[i].force_B).dot(j.axis_J);
      P += tau_d * j.motion->at(t).f_dot;
    }
    ts.push_back(t), Es.push_back(E.T + E.V), Ps.push_back(P);
    scale = std::max(scale, std::abs(E.T) + std::abs(E.V));
    return true;
  });
  REQUIRE(ts.size() == 4001);
  double work = 0, worst = 0, work_total = 0;
  for (std::size_t k = 2; k < ts.size(); k += 2) {
    work += (ts[k] - ts[k - 2]) / 6.0 * (Ps[k - 2] + 4 * Ps[k - 1] + Ps[k]);
    worst = std::max(worst, std::abs(Es[k] - Es[0] - work));
    work_total = std::max(work_total, std::abs(work));
  }
  INFO("drivers' work up to " << work_total << " J, largest |E - E0 - W| " << worst << " J, scale " << scale);
  CHECK(work_total > 1.0);           // the drivers really work
  CHECK(worst < 1e-8 * scale);       // Simpson's rule on 1 ms steps: ~1e-11 relative
}

TEST_CASE("simulate writes the prescribed coordinates after the q's", "[prescribed][cli]") {
  const Model model = load_model(test::source_path("tests/reference/v_prescribed_mix/v_prescribed_mix.yaml"));
  const auto cols = csv_columns(model);
  REQUIRE(model.has_prescribed());
  // t, the q's, then the prescribed coordinates named as their joint coordinate, then the u's
  for (std::size_t k = 0; k < model.prescribed_names.size(); ++k)
    CHECK(cols[1 + model.nq + k] == model.prescribed_names[k]);
  CHECK(cols[1 + model.nq + model.prescribed_names.size()] == model.u_names[0]);
  GenericEngine engine(model);
  SimulationOptions opt;
  opt.t_end = 1.0;
  opt.dt_out = 0.25;
  opt.integrator.kind = IntegratorKind::arkode_erk;
  std::ostringstream csv;
  simulate(engine, initial_state(model), opt, csv);
  std::istringstream in(csv.str());
  std::string line;
  std::getline(in, line);
  for (int row = 0; std::getline(in, line); ++row) {
    std::vector<double> v;
    std::stringstream ls(line);
    for (std::string cell; std::getline(ls, cell, ',');) v.push_back(std::stod(cell));
    std::size_t c = 1 + model.nq;
    for (const Body& b : model.bodies)
      if (b.joint.prescribed()) CHECK(v[c++] == Approx(b.joint.motion->at(v[0]).f).epsilon(1e-15));
  }
}

TEST_CASE("built-in beam: torsion modes and foreshortening against the continuous beam", "[flexible][beam]") {
  BeamSpec b;
  b.length = 2.0;
  b.axis = 0;
  b.mass_per_length = 0.8;
  b.EI = {50.0, 80.0};
  b.GJ = 30.0;
  b.polar_inertia = 0.002;
  b.elements = 60;
  b.modes = 8;
  const FlexibleData f = beam_modal_data(b);
  // Torsion (Saint-Venant, clamped-free): f_n = (2n - 1)/(4 L) sqrt(GJ / rhoJ).
  const double f_torsion = 1.0 / (4 * b.length) * std::sqrt(*b.GJ / *b.polar_inertia);
  int torsion = -1;
  for (int j = 0; j < f.modes(); ++j)
    if (f.Phi.col(j).isZero(0.0) && !f.Psi.col(j).isZero(0.0)) torsion = torsion < 0 ? j : torsion;
  REQUIRE(torsion >= 0);
  CHECK(f.frequency_hz(torsion) == Approx(f_torsion).epsilon(2e-3));  // lumped inertia: O(1/n^2) low
  // its modal mass is all rotary: Psi^T J Psi = 1
  const Eigen::VectorXd Y = modal_masses(f);
  CHECK(Y(torsion) == Approx(1.0).epsilon(1e-12));

  // Foreshortening of the first bending mode (about y: deflection along -z):
  // the tip moves along the beam by -1/2 Integral w'^2 ds; for the continuous
  // mode scaled to tip deflection w_L, Integral_0^L phi'^2 ds = kappa w_L^2 / L
  // with kappa from the exact clamped-free mode shape (computed here by quadrature).
  const double beta = 1.8751040687119611 / b.length;
  const double sigma = (std::cosh(beta * b.length) + std::cos(beta * b.length)) /
                       (std::sinh(beta * b.length) + std::sin(beta * b.length));
  auto phi = [&](double x) {
    return std::cosh(beta * x) - std::cos(beta * x) - sigma * (std::sinh(beta * x) - std::sin(beta * x));
  };
  auto dphi = [&](double x) {
    return beta * (std::sinh(beta * x) + std::sin(beta * x) - sigma * (std::cosh(beta * x) - std::cos(beta * x)));
  };
  double integral = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double x = (i + 0.5) * b.length / n;
    integral += dphi(x) * dphi(x) * b.length / n;
  }
  const double kappa = integral * b.length / (phi(b.length) * phi(b.length));
  const int tip = b.elements;
  const double w_tip = f.Phi.block<3, 1>(3 * tip, 0).norm();
  REQUIRE(f.has_second_order(tip));
  const double gamma = f.Gamma[tip][0](0, 0);  // along x: -Integral w'^2 for unit eta
  CHECK(gamma < 0);
  CHECK(-gamma == Approx(kappa * w_tip * w_tip / b.length).epsilon(2e-3));
  // Only bending modes of the same plane couple; the root node has none.
  CHECK_FALSE(f.has_second_order(0));
  CHECK(f.Gamma[tip][1].size() == 0);
  CHECK(f.Gamma[tip][2].size() == 0);
}

TEST_CASE("kanegen modes exports a beam (node inertias, second_order) that behaves as the built-in one",
          "[flexible][beam][cli]") {
  const std::string built_in = R"(
name: beam_export
gravity: [0, 0, -9.81]
bodies:
  - name: hub
    parent: ground
    joint: {type: revolute, axis: [0, 0, 1]}
    mass: 1.0
    inertia: [0.1, 0.1, 0.1, 0, 0, 0]
  - name: boom
    parent: hub
    joint: {type: fixed, position: [0.1, 0, 0]}
    flexible:
      beam: {length: 1.5, direction: x, mass_per_length: 0.4, EI: [9.0, 12.0], GJ: 4.0,
             rotary_inertia_per_length: [1e-4, 1.5e-4], elements: 12, modes: 5}
      damping_ratio: 0.02
  - name: tip
    parent: boom
    joint: {type: revolute, node: 13, axis: [0, 1, 0]}
    mass: 0.1
    inertia: [0.001, 0.001, 0.001, 0, 0, 0]
)";
  const std::string a = test::write_temp("beam_export.yaml", built_in);
  const std::string modal = test::write_temp("beam_export_boom.modal.yaml", "");
  const std::string cmd = std::string(kanegen::test::kanegen_binary()) + " modes " + a + " --body boom -o " + modal + " > /dev/null";
  REQUIRE(std::system(cmd.c_str()) == 0);
  std::string exported = built_in;
  const auto p0 = exported.find("      beam:"), p1 = exported.find("      damping_ratio");
  exported.replace(p0, p1 - p0, "      modal: " + modal + "\n");
  const Model ma = load_model(a), mb = load_model(test::write_temp("beam_export_modal.yaml", exported));
  REQUIRE(mb.bodies[1].flex->has_second_order(12));
  GenericEngine ea(ma), eb(mb);
  State s = initial_state(ma);
  for (int i = 0; i < ma.nq; ++i) s.q(i) = 0.1 * std::sin(1.0 + i);
  for (int i = 0; i < ma.nu; ++i) s.u(i) = 0.5 * std::cos(2.0 + i);
  MatX M1, M2;
  VecX F1, F2;
  ea.mass_matrix(s.q, M1);
  eb.mass_matrix(s.q, M2);
  ea.forcing(s.q, s.u, s.tau, F1);
  eb.forcing(s.q, s.u, s.tau, F2);
  CHECK(test::rel_err(M2, M1) < test::kRoundoff);
  CHECK(test::rel_err(F2, F1) < test::kRoundoff);
}

TEST_CASE("second_order from the shapes of a chain of nodes equals the beam's own", "[flexible][beam]") {
  BeamSpec b;
  b.length = 1.7;
  b.axis = 1;
  b.sign = -1;  // along -y
  b.mass_per_length = 0.3;
  b.EI = {4.0, 7.0};
  b.rotary_inertia = {2e-4, 3e-4};
  b.GJ = 2.0;
  b.elements = 9;
  b.modes = 6;
  const FlexibleData beam = beam_modal_data(b);
  FlexibleData f = beam;
  f.Gamma.assign(f.nodes.size(), {});
  // the nodes listed out of order: the chain is found from the geometry
  std::swap(f.nodes[3], f.nodes[7]);
  for (int i = 0; i < f.modes(); ++i) {
    f.Phi.block<3, 1>(9, i).swap(f.Phi.block<3, 1>(21, i));
    f.Psi.block<3, 1>(9, i).swap(f.Psi.block<3, 1>(21, i));
  }
  compute_chain_second_order(f);
  for (int k = 0; k <= b.elements; ++k) {
    const int kb = k == 3 ? 7 : k == 7 ? 3 : k;  // the same node in the beam's order
    for (int a = 0; a < 3; ++a) {
      INFO("node " << f.nodes[k].id << " axis " << a);
      const MatX& G = f.Gamma[k][a];
      const MatX& Gb = beam.Gamma[kb][a];
      REQUIRE(G.size() == Gb.size());
      if (G.size()) CHECK(test::rel_err(G, Gb) < test::kRoundoff);
    }
  }
  // A branch is refused, saying why: the tip node moved beside node 5 (nodes 4 and 5 get three neighbours).
  FlexibleData t = beam;
  t.nodes[9].rho_B = t.nodes[4].rho_B + Vec3(0.15, 0, 0);
  CHECK_THROWS_WITH(compute_chain_second_order(t), Catch::Contains("has 3 neighbours (a branch"));
}
