// Sweeps in C++ (sim/sweep.hpp): one draw for a group of parameters,
// correlated normal draws, dispersed inputs, the closed loop (a control law
// per run), and the run-time limit. The command-line sweep (threads, MPI,
// shards, resume) is tests/apps/test_sweep.py.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/orbit.hpp"
#include "model/sweep_spec.hpp"
#include "sim/row_sink.hpp"
#include "sim/simulate.hpp"
#include "sim/sweep.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

std::string slew_sweep(const std::string& body) {
  return "model: " + test::source_path("models/gnc/slew_spacecraft.yaml") + "\n" + body;
}

/// A continuous PD law on the wheel motors toward 10 deg about z (the bus rate and attitude from the sensors).
Controller pd_law(const Model& m) {
  const int att = m.output_index("star_tracker.qw"), gyro = m.output_index("gyro.x"), motor = m.input_index("motor_x");
  Controller c;
  c.law = [=](double, const VecX&, const VecX&, const VecX& y, VecX& w) {
    const double half = 5.0 * M_PI / 180.0;
    const Eigen::Quaterniond target(std::cos(half), 0, 0, std::sin(half));
    Eigen::Quaterniond e = target.conjugate() * Eigen::Quaterniond(y(att), y(att + 1), y(att + 2), y(att + 3));
    if (e.w() < 0) e.coeffs() = -e.coeffs();
    const Eigen::Vector3d torque = -(2.0 * 2.0 * e.vec() + 40.0 * Eigen::Vector3d(y.segment<3>(gyro)));
    w.segment<3>(motor) = -torque;
  };
  return c;
}

}  // namespace

TEST_CASE("sweep: one draw for a parameter group, correlated normals, dispersed inputs", "[sweep]") {
  const SweepPlan plan = plan_sweep(load_sweep_spec(test::write_temp("group.yaml", slew_sweep(R"(
runs: 4000
t_end: 1.0
dispersions:
  - {parameter: bus.inertia.xx, distribution: normal, sigma: 0.05, relative: true}
  - {parameter: bus.inertia.yy, distribution: normal, sigma: 0.05, relative: true}
  - name: damping
    parameter: [array_a.damping_ratio, array_b.damping_ratio]
    distribution: uniform
    low: -0.003
    high: 0.015
  - {parameter: inputs.motor_z, distribution: normal, sigma: 0.1}
correlations:
  - {between: [bus.inertia.xx, bus.inertia.yy], rho: 0.6}
)"))));
  REQUIRE(plan.targets.size() == 4);
  CHECK(plan.targets[2].size() == 6);  // three modes per array, one draw for all six
  double sxx = 0, syy = 0, sxy = 0, sm = 0;
  const double Ixx = plan.targets[0][0].nominal, Iyy = plan.targets[1][0].nominal;
  const long n = 4000;
  for (long k = 0; k < n; ++k) {
    const RunSetup s = run_setup(plan, k);
    const std::vector<double> v = draw(plan, k);
    // every member of the group: nominal + the same d
    const double d = s.parameters(plan.targets[2][0].index) - plan.targets[2][0].nominal;
    CHECK(d >= -0.003 - 1e-15);
    CHECK(d <= 0.015 + 1e-15);
    for (const auto& t : plan.targets[2]) CHECK(s.parameters(t.index) == t.nominal + d);
    CHECK(v[2] == s.parameters(plan.targets[2][0].index));
    CHECK(s.state.w(plan.model.input_index("motor_z")) == v[3]);
    const double a = (v[0] / Ixx - 1) / 0.05, b = (v[1] / Iyy - 1) / 0.05;
    sxx += a * a, syy += b * b, sxy += a * b, sm += v[3];
  }
  const double rho = sxy / std::sqrt(sxx * syy);
  INFO("sample correlation " << rho << " (4000 draws; standard error about 0.01)");
  CHECK(std::abs(rho - 0.6) < 0.05);
  CHECK(std::abs(std::sqrt(sxx / n) - 1.0) < 0.05);  // the marginals stay N(0, 1) in sigma units
  CHECK(std::abs(sm / n) < 4 * 0.1 / std::sqrt(double(n)));

  // coefficients no joint distribution has are refused, naming the field
  const std::string bad = test::write_temp("bad_corr.yaml", slew_sweep(R"(
runs: 2
t_end: 1.0
dispersions:
  - {parameter: bus.inertia.xx, distribution: normal, sigma: 0.05, relative: true}
  - {parameter: bus.inertia.yy, distribution: normal, sigma: 0.05, relative: true}
  - {parameter: bus.inertia.zz, distribution: normal, sigma: 0.05, relative: true}
correlations:
  - {between: [bus.inertia.xx, bus.inertia.yy], rho: 0.9}
  - {between: [bus.inertia.yy, bus.inertia.zz], rho: 0.9}
  - {between: [bus.inertia.xx, bus.inertia.zz], rho: -0.9}
)"));
  CHECK_THROWS_WITH(plan_sweep(load_sweep_spec(bad)), Catch::Contains("positive definite"));
  const std::string twice = test::write_temp("twice.yaml", slew_sweep(R"(
runs: 2
t_end: 1.0
dispersions:
  - {parameter: array_a.damping_ratio, distribution: normal, sigma: 0.001}
  - {parameter: array_a.damping_ratio2, distribution: normal, sigma: 0.001}
)"));
  CHECK_THROWS_WITH(plan_sweep(load_sweep_spec(twice)), Catch::Contains("dispersed twice"));
}

TEST_CASE("sweep: a closed-loop run equals a single simulate of its draw, 1 and 2 threads agree", "[sweep][generated]") {
  const SweepPlan plan = plan_sweep(load_sweep_spec(test::write_temp("closed.yaml", slew_sweep(R"(
runs: 4
seed: 3
t_end: 20.0
dt_out: 0.5
integrator: rkf78
rtol: 1.0e-9
atol: 1.0e-11
dispersions:
  - {parameter: bus.inertia.zz, distribution: normal, sigma: 0.1, relative: true}
  - {parameter: [array_a.damping_ratio, array_b.damping_ratio], distribution: uniform, low: 0.0, high: 0.01}
metrics:
  - {name: qz, column: star_tracker.qz, stat: final}
  - {name: peak_motor, column: motor_z, stat: absmax}
  - {name: H, column: Hz, stat: final}
)"))));
  const ControllerFactory law = [](const Model& m, long) { return pd_law(m); };
  auto engine = test::generated_engine(plan.model);
  for (long k = 0; k < 4; ++k) {
    const RunResult r = run_one(*engine, plan, k, nullptr, law);
    REQUIRE(r.ok());
    // the same run by hand: its parameters, state and the law, simulate() into a table
    RunSetup s = run_setup(plan, k);
    GenericEngine generic(plan.model);
    generic.set_parameters(s.parameters);
    s.options.controller = pd_law(plan.model);
    RowTable table;
    simulate(generic, s.state, s.options, table);
    const double qz = table.column("star_tracker.qz").back();
    INFO("run " << k << ": sweep (generated) " << r.metrics[0] << ", simulate (generic) " << qz);
    CHECK(std::abs(r.metrics[0] - qz) <= 1e-8);
    CHECK(r.metrics[0] > 0.02);  // the slew is under way toward sin(5 deg) = 0.087 (0.027 after 20 s)
  }
  std::vector<RunResult> threaded(4);
  run_on_threads(
      plan, {0, 1, 2, 3}, 2, [](const Model& m) { return std::unique_ptr<Engine>(test::generated_engine(m)); },
      [&](RunResult&& r) { threaded[r.index] = std::move(r); }, law);
  for (long k = 0; k < 4; ++k) {
    CHECK(threaded[k].values == run_one(*engine, plan, k, nullptr, law).values);
    CHECK(threaded[k].metrics == run_one(*engine, plan, k, nullptr, law).metrics);  // bit for bit
  }
}

TEST_CASE("sweep: a run past its wall-time limit is recorded as failed, with the reason", "[sweep]") {
  const SweepPlan plan = plan_sweep(load_sweep_spec(test::write_temp("limit.yaml", slew_sweep(R"(
runs: 1
t_end: 1.0e7
dt_out: 1000.0
integrator: rkf78
rtol: 1.0e-12
atol: 1.0e-14
run_time_limit: 0.5
dispersions:
  - {parameter: u.bus.wz, distribution: normal, sigma: 0.01}
)"))));
  GenericEngine engine(plan.model);
  const RunResult r = run_one(engine, plan, 0);
  INFO(r.status);
  CHECK_FALSE(r.ok());
  CHECK(r.status.find("wall-time limit of 0.5 s") != std::string::npos);
  CHECK(r.wall_s < 5.0);
}

TEST_CASE("sweep: orbit elements and LVLH offsets dispersed by name, each run's centre of mass on its own orbit, "
          "the root's state under an orbit refused",
          "[sweep][central]") {
  const std::string model = test::source_path("models/gravity_gradient_boom.yaml");
  const SweepPlan plan = plan_sweep(load_sweep_spec(test::write_temp("orbit_sweep.yaml", "model: " + model + R"(
runs: 12
t_end: 1.0
engine: generic
dispersions:
  - {parameter: orbit.a, distribution: normal, sigma: 1.0e4}
  - {parameter: orbit.i, distribution: uniform, low: -0.1, high: 0.1}
  - {parameter: orbit.nu, distribution: uniform, low: 0.0, high: 6.0}
  - {parameter: orbit.attitude_offset.y, distribution: normal, sigma: 0.05}
  - {parameter: orbit.rate_offset.z, distribution: normal, sigma: 1.0e-3}
  - {parameter: tip.mass, distribution: normal, sigma: 0.2, relative: true}
)")));
  const Model& m = plan.model;
  REQUIRE(m.initial_orbit);
  const double mu = m.central->mu;
  for (long k = 0; k < 12; ++k) {
    INFO("run " << k);
    const RunSetup s = run_setup(plan, k);
    REQUIRE(s.failure.empty());
    const std::vector<double> v = draw(plan, k);
    OrbitElements el = m.initial_orbit->elements;
    el.a = v[0], el.i = v[1], el.nu = v[2];
    const OrbitState target = state_from_elements(mu, el);
    // the centre of mass (this run's tip mass) and its velocity, from the generic engine with its parameters
    GenericEngine e(m);
    e.set_parameters(s.parameters);
    const MomentumValues P = e.momentum(0.0, s.state.q, s.state.u);
    const double mass = 100.0 + 1.0 + v[5];
    CHECK((P.p_N / mass - target.v_N).norm() <= 1e-10 * target.v_N.norm());
    const Mat3 R_NB = Eigen::Quaterniond(s.state.q(3), s.state.q(4), s.state.q(5), s.state.q(6)).toRotationMatrix();
    const Mat3 R_LB = lvlh_frame(target).transpose() * R_NB;
    CHECK((R_LB - Eigen::AngleAxisd(v[3], Vec3::UnitY()).toRotationMatrix()).norm() <= 1e-12);
    const Vec3 w_rel = s.state.u.segment<3>(3) - R_NB.transpose() * lvlh_rate_N(target);
    CHECK((w_rel - Vec3(0, 0, v[4])).norm() <= 1e-15);
  }
  // the root's own state is the orbit's: refused, as initial: refuses it
  for (const char* name : {"u.bus.wx", "q.bus.x", "u.bus.vz"})
    CHECK_THROWS_WITH(plan_sweep(load_sweep_spec(test::write_temp("orbit_bad.yaml", "model: " + model + R"(
runs: 2
t_end: 1.0
dispersions:
  - {parameter: )" + name + R"(, distribution: normal, sigma: 1.0e-3}
)"))),
                      Catch::Contains("is set by the model's initial.orbit"));
  CHECK_THROWS_WITH(plan_sweep(load_sweep_spec(test::write_temp("orbit_bad.yaml", "model: " + model + R"(
runs: 2
t_end: 1.0
dispersions:
  - {parameter: orbit.inclination, distribution: normal, sigma: 1.0e-3}
)"))),
                    Catch::Contains("expected orbit.a, .e, .i"));
  // an eccentricity dispersed below 0 fails that run, with its reason
  const SweepPlan bad = plan_sweep(load_sweep_spec(test::write_temp("orbit_e.yaml", "model: " + model + R"(
runs: 1
t_end: 1.0
dispersions:
  - {parameter: orbit.e, distribution: uniform, low: -0.2, high: -0.1}
)")));
  CHECK_THAT(run_setup(bad, 0).failure, Catch::Contains("the run's orbit"));
}
