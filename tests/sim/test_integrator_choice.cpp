// `--integrator auto` and the run's error estimate.
#include <catch2/catch.hpp>

#include <fstream>
#include <iterator>

#include <sstream>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "sim/integrator_choice.hpp"
#include "sim/simulate.hpp"
#include "sim/work_precision.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

/// A rod on a hinge with a spring k and a damper c: lambda = (-c +- sqrt(c^2 - 4 k I)) / (2 I).
std::string damped_hinge(double k, double c) {
  return "name: damped_hinge\n"
         "bodies:\n"
         "  - name: rod\n"
         "    parent: ground\n"
         "    joint: {type: revolute, axis: [0, 0, 1], stiffness: " + std::to_string(k) +
         ", damping: " + std::to_string(c) + "}\n"
         "    mass: 1.0\n"
         "    com: [0.5, 0, 0]\n"
         "    inertia: [0.001, 0.001, 0.001, 0, 0, 0]\n"
         "initial:\n"
         "  q: {rod.angle: 0.3}\n";
}

}  // namespace

TEST_CASE("auto: a non-stiff scene goes to an explicit method and the reason says why", "[integrators]") {
  {
    const Model m = load_model(test::source_path("models/explorer1_rigid.yaml"));
    GenericEngine e(m);
    const IntegratorChoice c = choose_integrator(e, initial_state(m), 10.0, 0.01, 1e-8);
    CHECK(c.kind == IntegratorKind::rkf78);
    CHECK_THAT(c.reason, Catch::Contains("non-stiff"));
    CHECK(choose_integrator(e, initial_state(m), 10.0, 0.01, 1e-4).kind == IntegratorKind::dopri5);
  }
}

TEST_CASE("auto: a stiff scene goes to BDF and the reason says why", "[integrators]") {
  {
    // I = 0.001 + 0.25 = 0.251 about the hinge; c = 1000: lambda ~ -c/I = -3984 and -k/c = -0.001.
    const Model m = load_model(test::write_temp("stiff_hinge.yaml", damped_hinge(1.0, 1000.0)));
    GenericEngine e(m);
    const IntegratorChoice c = choose_integrator(e, initial_state(m), 1000.0, 1.0, 1e-8);
    CHECK(c.kind == IntegratorKind::cvode_bdf);
    CHECK(c.fastest_decay == Approx(1000.0 / 0.251).epsilon(1e-3));
    CHECK(c.explicit_steps == Approx(1000.0 / 0.251 * 1000.0 / 3.3).epsilon(1e-3));
    CHECK_THAT(c.reason, Catch::Contains("stiff") && Catch::Contains("cvode-bdf"));
  }
}

TEST_CASE("auto: a fast undamped oscillation stays explicit over 1000 s", "[integrators]") {
  {
    // Undamped, k = 1e8: an oscillation at 2e4 rad/s over 1000 s -> 6e6 steps: still explicit.
    const Model m = load_model(test::write_temp("fast_hinge.yaml", damped_hinge(1e8, 0.0)));
    GenericEngine e(m);
    const IntegratorChoice c = choose_integrator(e, initial_state(m), 1000.0, 1.0, 1e-8);
    CHECK(c.spectral_radius == Approx(std::sqrt(1e8 / 0.251)).epsilon(1e-6));
    CHECK(c.kind == IntegratorKind::rkf78);
  }
}

TEST_CASE("auto: the same oscillation over 1e5 s goes to BDF2 with a reason that warns of its damping", "[integrators]") {
  {
    // the fast hinge above over 1e5 s (6e8 steps): BDF2, whose reason warns of its numerical damping.
    const Model m = load_model(test::write_temp("fast_hinge.yaml", damped_hinge(1e8, 0.0)));
    GenericEngine e(m);
    const IntegratorChoice c2 = choose_integrator(e, initial_state(m), 1e5, 1.0, 1e-8);
    CHECK(c2.kind == IntegratorKind::cvode_bdf2);
    CHECK_THAT(c2.reason, Catch::Contains("damps"));
  }
}

TEST_CASE("simulate: the error estimate is within 10x of the true error, drifts reported", "[integrators]") {
  const Model m = load_model(test::source_path("models/explorer1_rigid.yaml"));
  GenericEngine e(m);
  const State s0 = initial_state(m);
  SimulationOptions o;
  o.t_end = 10.0;
  o.dt_out = 0.1;
  o.integrator.kind = IntegratorKind::automatic;
  o.integrator.rtol = 1e-6;
  o.integrator.atol = 1e-8;
  o.estimate_error = true;
  std::ostringstream csv;
  const SimulationResult r = simulate(e, s0, o, csv);
  CHECK(r.stats.integrator == "rkf78");
  CHECK_THAT(r.quality.integrator_choice, Catch::Contains("non-stiff"));
  // explorer1_rigid: free, no gravity, dampers: |H| holds, energy does not
  CHECK(std::isnan(r.quality.energy_drift));
  REQUIRE(std::isfinite(r.quality.H_drift));
  CHECK(r.quality.H_drift < 1e-4);
  REQUIRE(std::isfinite(r.quality.error_estimate));

  // the true error, against a run at rtol 1e-13, measured as kanegen bench does
  auto trajectory = [&](IntegratorKind kind, double rtol) {
    bench::Trajectory tr;
    std::string failure;
    IntegratorOptions io;
    io.kind = kind;
    io.rtol = rtol;
    io.atol = rtol * 1e-2;
    VecX x0(m.nq + m.nu);
    x0 << s0.q, s0.u;
    integrate(make_ode_problem(e, s0.tau, &failure), io, 0.0, x0, o.t_end, o.dt_out, [&](double t, const VecX& x) {
      tr.t.push_back(t);
      tr.x.push_back(x);
      return true;
    });
    return tr;
  };
  const double truth = bench::trajectory_error(m, trajectory(IntegratorKind::rkf78, 1e-6),
                                               trajectory(IntegratorKind::rkf78, 1e-13))
                           .error;
  INFO("estimate " << r.quality.error_estimate << ", true error " << truth);
  CHECK(r.quality.error_estimate > truth / 10);
  CHECK(r.quality.error_estimate < truth * 10);
  CHECK_THAT(r.quality.summary(), Catch::Contains("|H| drift") && Catch::Contains("estimated error"));
}

TEST_CASE("auto: a spinning spacecraft with strongly damped whips is accuracy-bound, not stiff: explicit",
          "[integrators]") {
  // The physical Explorer I with 3 mm whips and 5 % damping over 12,000 s: the
  // dominant eigenvalue (-149, a damped whip mode) would hold an explicit
  // method to 5e5 steps, but following the spin-rate oscillations at rtol
  // 1e-10 takes far more (rkf78: 2.5 million steps, 2.8x faster and 23,000x
  // more accurate than cvode-bdf's 19.9 million, issue 19).
  const Model m = load_model(test::source_path("models/extreme/explorer1_damped_whips.yaml"));
  GenericEngine e(m);
  const IntegratorChoice c = choose_integrator(e, initial_state(m), 12000.0, 1.0, 1e-10);
  INFO(c.reason);
  CHECK(c.fastest_decay > 100.0);
  CHECK(c.explicit_steps > 1e5);                 // the old rule's "stiff"
  CHECK(c.resolved_steps_bdf > 3 * c.explicit_steps);
  CHECK(c.kind == IntegratorKind::rkf78);
  CHECK_THAT(c.reason, Catch::Contains("accuracy-bound"));
}

TEST_CASE("auto: variants of the physical Explorer I (stiffer, more damped whips, twice the spin) stay explicit",
          "[integrators]") {
  // The same scene made harder both ways: the whips' modes faster and more
  // damped (EI x4, 20 % damping), or the spin doubled. The spin-rate
  // oscillations still set the step (accuracy-bound), so BDF would gain
  // nothing (scripts/speed_report.py times auto against every method on them).
  std::ifstream in(test::source_path("models/extreme/explorer1_damped_whips.yaml"));
  const std::string base((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto variant = [&](const std::string& name, std::vector<std::pair<std::string, std::string>> subs) {
    std::string text = base;
    for (const auto& [a, b] : subs) {
      REQUIRE(text.find(a) != std::string::npos);
      for (std::size_t at; (at = text.find(a)) != std::string::npos;) text.replace(at, a.size(), b);
    }
    return load_model(test::write_temp(name + ".yaml", text));
  };
  const Model stiff = variant("whips_stiff_damped", {{"EI: [0.7952156404, 0.7952156404]", "EI: [3.1808625616, 3.1808625616]"},
                                                     {"damping_ratio: 0.05", "damping_ratio: 0.2"}});
  const Model spin = variant("whips_high_spin", {{"bus.wz: 78.539816339744831", "bus.wz: 157.07963267948966"}});
  for (const Model* m : {&stiff, &spin}) {
    GenericEngine e(*m);
    const IntegratorChoice c = choose_integrator(e, initial_state(*m), 12000.0, 1.0, 1e-10);
    INFO(m->source_path << ": " << c.reason);
    CHECK(c.resolved_steps_bdf > c.explicit_steps);
    CHECK(c.kind == IntegratorKind::rkf78);
  }
}

TEST_CASE("auto: a fast, lightly damped oscillation hardly excited goes to arkode-dirk by a probe, and the run "
          "keeps rkf78's accuracy",
          "[integrators]") {
  // models/extreme/stiff_appendage.yaml over 10 s: a 7.8 kHz appendage mode
  // would hold rkf78 to 1.5e5 steps; the probe projects DIRK's cost far
  // below and finds both ending together (docs/speed.md: rkf78 2.0 s,
  // arkode-dirk 0.21 s at the same estimated error)
  const Model m = load_model(test::source_path("models/extreme/stiff_appendage.yaml"));
  GenericEngine e(m);
  const IntegratorChoice c = choose_integrator(e, initial_state(m), 10.0, 0.1, 1e-10);
  INFO(c.reason);
  CHECK(c.kind == IntegratorKind::arkode_dirk);
  CHECK(c.probe_dirk_evals * 1.5 < c.probe_rkf78_evals);
  CHECK(c.probe_difference < 1e-6);
  // the probe is deterministic (right-hand sides, not wall time): the same choice again
  const IntegratorChoice again = choose_integrator(e, initial_state(m), 10.0, 0.1, 1e-10);
  CHECK(again.probe_dirk_evals == c.probe_dirk_evals);
  CHECK(again.probe_rkf78_evals == c.probe_rkf78_evals);
}
