// simulate() at its edges: a model without degrees of freedom.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <fstream>
#include <iterator>
#include <sstream>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "sim/row_sink.hpp"
#include "sim/simulate.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

TEST_CASE("simulate: a model without degrees of freedom writes its rows (prescribed motion, reactions)", "[simulate]") {
  // a hub driven at a prescribed sine, carrying a rigid arm on a fixed joint:
  // nq = nu = 0; the rows hold the prescribed angle f(t) and the reaction
  // torque about the hub axis, J_O f''(t) (J_O of hub and arm about the axis)
  const Model model = load_model(test::write_temp("no_dof.yaml", R"(
name: no_dof
bodies:
  - name: hub
    parent: ground
    joint: {type: revolute, axis: [0, 0, 1], motion: {sine: {amplitude: 0.3, frequency: 0.5}}}
    mass: 2.0
    inertia: [0.1, 0.1, 0.2, 0, 0, 0]
  - name: arm
    parent: hub
    joint: {type: fixed, position: [0.5, 0, 0]}
    mass: 1.0
    com: [0.25, 0, 0]
    inertia: [0.001, 0.02, 0.02, 0, 0, 0]
outputs: [reactions]
)"));
  REQUIRE(model.nq == 0);
  REQUIRE(model.nu == 0);
  GenericEngine engine(model);
  SimulationOptions o;
  o.t_end = 2.0;
  o.dt_out = 0.25;
  std::ostringstream csv;
  const SimulationResult r = simulate(engine, initial_state(model), o, csv);
  CHECK(r.rows == 9);
  std::istringstream in(csv.str());
  std::string line;
  std::getline(in, line);
  CHECK(line.rfind("t,hub.angle,hub.fx", 0) == 0);
  const double w = 2 * M_PI * 0.5, J = 0.2 + 0.02 + 1.0 * 0.75 * 0.75;  // hub + arm about the axis
  for (int k = 0; std::getline(in, line); ++k) {
    std::vector<double> v;
    std::istringstream ls(line);
    for (std::string cell; std::getline(ls, cell, ',');) v.push_back(std::stod(cell));
    const double t = 0.25 * k;
    INFO("t = " << t);
    CHECK(std::abs(v[0] - t) <= 1e-12);
    CHECK(std::abs(v[1] - 0.3 * std::sin(w * t)) <= 1e-12);
    CHECK(std::abs(v[7] - J * (-0.3 * w * w * std::sin(w * t))) <= 1e-9);  // hub.tz
  }
}

TEST_CASE("simulate: the summary keeps the invariants physics keeps and names what rules the others out", "[simulate]") {
  SECTION("wheel motors under a controller are internal torques: H kept (to round-off), energy not") {
    const Model model = load_model(test::source_path("models/gnc/slew_spacecraft.yaml"));
    GenericEngine engine(model);
    State s = initial_state(model);
    s.u(model.speed_index("bus.wz")) = 0.01;
    SimulationOptions o;
    o.t_end = 20.0;
    o.dt_out = 1.0;
    o.integrator.kind = IntegratorKind::rkf78;
    const int gyro = model.output_index("gyro.x"), motor = model.input_index("motor_x");
    o.controller.law = [=](double, const VecX&, const VecX&, const VecX& y, VecX& w) {
      w.segment<3>(motor) = 30.0 * y.segment<3>(gyro);  // rate damping through the wheels
    };
    RowTable rows;
    const SimulationResult r = simulate(engine, s, o, rows);
    const auto wz = rows.column("gyro.z");
    CHECK(std::abs(wz.back()) < 0.6 * std::abs(wz.front()));  // the law did act (time constant about 29 s)
    INFO(r.quality.summary());
    CHECK(r.quality.H_drift < 1e-10);
    CHECK(std::isnan(r.quality.energy_drift));
    CHECK(r.quality.invariants_note.find("energy not conserved") != std::string::npos);
    CHECK(r.quality.invariants_note.find("modal damping of 2 flexible bodies") != std::string::npos);
    CHECK(r.quality.invariants_note.find("a controller setting 3 inputs") != std::string::npos);
    CHECK(r.quality.invariants_note.find("p, H") == std::string::npos);
  }
  SECTION("prescribed motion: energy not conserved, named; no 'energy drift 1'; E - E0 = the driver's work") {
    const Model model = load_model(test::write_temp("driven_arm.yaml", R"(
name: driven_arm
gravity: [0, 0, 0]
bodies:
  - name: hub
    parent: ground
    joint: {type: revolute, axis: [0, 0, 1], motion: {sine: {amplitude: 0.3, frequency: 0.5}}}
    mass: 2.0
    inertia: [0.1, 0.1, 0.2, 0, 0, 0]
  - name: arm
    parent: hub
    joint: {type: revolute, axis: [0, 0, 1], position: [0.5, 0, 0], stiffness: 2.0}
    mass: 1.0
    com: [0.25, 0, 0]
    inertia: [0.001, 0.02, 0.02, 0, 0, 0]
outputs: [energy]
)"));
    GenericEngine engine(model);
    SimulationOptions o;
    o.t_end = 4.0;
    o.dt_out = 0.01;
    o.integrator.kind = IntegratorKind::rkf78;
    o.integrator.rtol = 1e-11;
    o.integrator.atol = 1e-13;
    RowTable rows;
    const SimulationResult r = simulate(engine, initial_state(model), o, rows);
    INFO(r.quality.summary());
    CHECK(std::isnan(r.quality.energy_drift));
    CHECK(r.quality.summary().find("energy drift") == std::string::npos);
    // the energy changes by the driver's work, and only by it: E - E0 - W stays at the integration error
    const auto T = rows.column("T"), V = rows.column("V");
    double swing = 0.0, scale = 0.0;
    for (std::size_t k = 0; k < T.size(); ++k) {
      swing = std::max(swing, std::abs(T[k] + V[k] - T[0] - V[0]));
      scale = std::max(scale, T[k] + std::abs(V[k]));
    }
    CHECK(swing > 0.1 * scale);
    // at dt_out = 0.01 the quadrature of W on the rows dominates (fourth order: 2.05e-7 here, 1.29e-8 at
    // 0.005, 8.1e-10 at 0.0025), and the summary's estimate of it says so
    CHECK(r.quality.energy_balance < 1e-6);
    CHECK(r.quality.energy_balance < 2.0 * r.quality.energy_balance_quadrature + 1e-10);
    CHECK(r.quality.energy_balance > 0.3 * r.quality.energy_balance_quadrature);
    // every row counts, not only the (at most 2000) states kept for the drifts: 4000 rows, the same balance
    o.t_end = 40.0;
    RowTable long_rows;
    const SimulationResult l = simulate(engine, initial_state(model), o, long_rows);
    CHECK(long_rows.rows() > 4000);
    CHECK(l.quality.energy_balance < 1e-6);
    CHECK(r.quality.summary().find("energy balance with the drivers' work") != std::string::npos);
    CHECK(r.quality.invariants_note.find("prescribed motion of hub") != std::string::npos);
    CHECK(r.quality.invariants_note.find("the root joint of hub is not free") != std::string::npos);
  }
  SECTION("a thruster is external: neither energy nor momenta") {
    const Model model = load_model(test::write_temp("thrust.yaml", R"(
name: thrust
gravity: [0, 0, 0]
bodies:
  - {name: sat, parent: ground, joint: {type: free}, mass: 10, inertia: [1, 2, 3, 0, 0, 0]}
inputs:
  - {name: thr, type: thruster, body: sat, point: [0, 0.5, 0], direction: [1, 0, 0]}
)"));
    GenericEngine engine(model);
    State s = initial_state(model);
    s.w(0) = 0.1;
    SimulationOptions o;
    o.t_end = 2.0;
    o.dt_out = 0.5;
    RowTable rows;
    const SimulationResult r = simulate(engine, s, o, rows);
    INFO(r.quality.summary());
    CHECK(std::isnan(r.quality.energy_drift));
    CHECK(std::isnan(r.quality.H_drift));
    CHECK(r.quality.invariants_note.find("p, H not conserved: external 1 input (thr)") != std::string::npos);
  }
}

TEST_CASE("simulate: a zero total H is no scale (no false alarm), in orbit the drifts are in J and N m s against "
          "the motion about the centre of mass, H_z alone with J2",
          "[simulate][central]") {
  // a wheel biased in the null space: H_z = 100 (-0.5 + 1e-12) + 0.5 * 100 = 1e-10 N m s, the wheel's own 50
  const Model wheel = load_model(test::write_temp("null_wheel.yaml", R"(name: null_wheel
gravity: [0, 0, 0]
bodies:
  - {name: bus, parent: ground, joint: {type: free}, mass: 100.0, inertia: [80, 90, 99.5, 0, 0, 0]}
  - {name: wheel, parent: bus, joint: {type: revolute, axis: [0, 0, 1]}, mass: 2.0, inertia: [0.3, 0.3, 0.5, 0, 0, 0]}
initial:
  u: {bus.wz: -0.499999999999, wheel.angle_rate: 100.0, bus.wx: 1.0e-13}
)"));
  {
    GenericEngine engine(wheel);
    const State s = initial_state(wheel);
    REQUIRE(engine.momentum(s.q, s.u).H_N.norm() < 1e-9);
    SimulationOptions o;
    o.t_end = 20.0;
    o.dt_out = 0.5;
    o.integrator.kind = IntegratorKind::rkf78;
    RowTable rows;
    const SimulationResult r = simulate(engine, s, o, rows);
    INFO(r.quality.summary());
    CHECK(r.quality.H_drift < 1e-10);
    CHECK(r.quality.H_scale_Nms >= 50.0);  // at least the wheel's own momentum
    CHECK(r.quality.H_drift_Nms <= r.quality.H_drift * r.quality.H_scale_Nms * (1 + 1e-12));
    CHECK_THAT(r.quality.summary(), Catch::Contains("N m s against a scale of"));
  }
  // in orbit with J2: H_z, and the scales are the libration's, not the orbit's
  const Model gg = load_model(test::source_path("models/gravity_gradient_boom.yaml"));
  GenericEngine engine(gg);
  SimulationOptions o;
  o.t_end = 200.0;
  o.dt_out = 10.0;
  o.integrator.kind = IntegratorKind::rkf78;
  RowTable rows;
  const SimulationResult r = simulate(engine, initial_state(gg), o, rows);
  INFO(r.quality.summary());
  CHECK(r.quality.about_com);
  CHECK(r.quality.H_z);
  CHECK(std::isnan(r.quality.energy_drift));  // the boom's modal damping
  // the orbit's H_z is 106 kg r v = 7.2e11 N m s; the motion about the centre of mass: I n, about 0.6 N m s
  CHECK(r.quality.H_total_Nms > 1e11);
  CHECK(r.quality.H_scale_Nms < 10.0);
  CHECK(r.quality.H_scale_Nms > 0.1);
  CHECK(r.quality.H_drift == Approx(r.quality.H_drift_Nms / r.quality.H_scale_Nms).epsilon(1e-12));
  CHECK_THAT(r.quality.summary(), Catch::Contains("H_z drift") && Catch::Contains("of the motion about the centre of mass"));
  // that drift is the orbit's round-off: within 10 sqrt(steps) ulps of H_z with the orbit, and the summary says so
  REQUIRE(r.quality.steps == r.stats.steps);
  REQUIRE(r.stats.steps > 0);
  const double ulp = std::numeric_limits<double>::epsilon() * r.quality.H_total_Nms;
  CHECK(r.quality.H_drift_Nms <= 10.0 * ulp * std::sqrt(static_cast<double>(r.stats.steps)));
  CHECK_THAT(r.quality.summary(), Catch::Contains("ulps of that total") && Catch::Contains("at the orbit's round-off"));
}

TEST_CASE("simulate: generated code without an energy output still reports H_z in orbit (measured on the generic "
          "engine)",
          "[simulate][central]") {
  // H_z alone (J2) with momentum but no energy among the outputs: the scales of the motion about the centre of
  // mass need T_c, which the generated code does not have; the run once failed at its end ("generated without
  // 'energy' output")
  std::ifstream in(test::source_path("models/gravity_gradient_boom.yaml"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("  - energy\n"), 11, "");
  const Model model = load_model(test::write_temp("boom_no_energy.yaml", text));
  REQUIRE_FALSE(model.outputs.energy);
  auto engine = test::generated_engine(model);
  SimulationOptions o;
  o.t_end = 200.0;
  o.dt_out = 10.0;
  o.integrator.kind = IntegratorKind::rkf78;
  RowTable rows;
  const SimulationResult r = simulate(*engine, initial_state(model), o, rows);
  INFO(r.quality.summary());
  CHECK(r.quality.H_z);
  CHECK(r.quality.about_com);
  CHECK(r.quality.H_scale_Nms > 0.1);
  CHECK(r.quality.H_scale_Nms < 10.0);
}
