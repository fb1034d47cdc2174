// Linear models (sim/linearize.hpp) against closed forms and against central
// differences: a pendulum's A and B, a free rigid body's nutation frequency
// in steady spin about a principal axis (and the growth rate about the
// intermediate axis), a clamped beam's natural frequencies, and the exact
// derivatives of the generated code against central differences of the
// generic engine on a model with every kind of input and output.
#include <catch2/catch.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "sim/linearize.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

State at(const Model& model, std::initializer_list<std::pair<const char*, double>> q,
         std::initializer_list<std::pair<const char*, double>> u = {}) {
  State s = initial_state(model);
  for (auto [n, v] : q) s.q(model.q_index(n)) = v;
  for (auto [n, v] : u) s.u(model.u_index(n)) = v;
  return s;
}

/// The eigenvalue of A nearest to z.
std::complex<double> nearest(const std::vector<LinearMode>& modes, std::complex<double> z) {
  std::complex<double> best = modes.at(0).eigenvalue;
  for (const auto& m : modes)
    if (std::abs(m.eigenvalue - z) < std::abs(best - z)) best = m.eigenvalue;
  return best;
}

std::string rigid_body(double Ix, double Iy, double Iz, const char* spin_axis, double rate) {
  return fmt::format(R"(
name: spinner
bodies:
  - {{name: sat, parent: ground, joint: {{type: free}}, mass: 10, inertia: [{}, {}, {}, 0, 0, 0]}}
initial:
  u: {{sat.{}: {}}}
)",
                     Ix, Iy, Iz, spin_axis, rate);
}

}  // namespace

TEST_CASE("linearize: a pendulum's A and B are the closed form", "[linearize]") {
  // theta_ddot = (g/L) cos(theta) + tau/(m L^2): A = [0 1; -(g/L) sin(theta) 0], B = [0; 1/(m L^2)]
  const Model model = load_model(test::source_path("models/pendulum.yaml"));
  auto engine = test::generated_engine(model);
  for (double theta : {M_PI / 2, 0.7, -2.0}) {
    INFO("theta = " << theta);
    const LinearModel lin = linearize(*engine, at(model, {{"bob.angle", theta}}), {});
    REQUIRE(lin.A.rows() == 2);
    CHECK(lin.A(0, 0) == 0.0);
    CHECK(lin.A(0, 1) == 1.0);
    CHECK(std::abs(lin.A(1, 0) - (-9.81 * std::sin(theta))) <= 1e-13);
    CHECK(std::abs(lin.A(1, 1)) <= 1e-15);
    REQUIRE(lin.B.cols() == 1);
    CHECK(lin.input_names[0] == "tau.bob.angle_rate");
    CHECK(std::abs(lin.B(1, 0) - 1.0) <= 1e-15);
    CHECK(lin.equilibrium == (theta == M_PI / 2));
    // hanging: the small-oscillation frequency sqrt(g/L)
    if (theta == M_PI / 2) {
      const auto modes = linear_modes(lin);
      REQUIRE(modes.size() == 1);
      CHECK(std::abs(modes[0].eigenvalue.imag() - std::sqrt(9.81)) <= 1e-12);
      CHECK(std::abs(modes[0].damping_ratio) <= 1e-12);
    }
  }
}

TEST_CASE("linearize: a free rigid body's nutation in steady spin about a principal axis", "[linearize]") {
  // Axisymmetric body, I_t = 3, I_s = 5, spin Omega about the symmetry axis:
  // body-frame nutation at Omega (I_s - I_t) / I_t; about the intermediate
  // axis of (2, 3, 5) the motion grows at Omega sqrt((I_y - I_x)(I_z - I_y) / (I_x I_z)).
  const double Omega = 2.5;
  {
    const Model model = load_model(test::write_temp("spin_major.yaml", rigid_body(3, 3, 5, "wz", Omega)));
    auto engine = test::generated_engine(model);
    const LinearModel lin = linearize(*engine, initial_state(model), {});
    CHECK(lin.A.rows() == 12);  // 6 + 6: the quaternion's tangent space, no constraint direction
    CHECK(lin.state_names[3] == "q.sat.rx");
    CHECK_FALSE(lin.equilibrium);  // the attitude turns: a first-order Taylor model
    const auto modes = linear_modes(lin);
    const double nutation = Omega * (5.0 - 3.0) / 3.0;
    const auto l = nearest(modes, {0.0, nutation});
    INFO("eigenvalue " << l << ", closed form " << nutation);
    CHECK(std::abs(l.imag() - nutation) <= 1e-12 * nutation);
    CHECK(std::abs(l.real()) <= 1e-12);
  }
  {
    const Model model = load_model(test::write_temp("spin_mid.yaml", rigid_body(2, 3, 5, "wy", Omega)));
    auto engine = test::generated_engine(model);
    const auto modes = linear_modes(linearize(*engine, initial_state(model), {}));
    const double growth = Omega * std::sqrt((3.0 - 2.0) * (5.0 - 3.0) / (2.0 * 5.0));
    const auto l = nearest(modes, {growth, 0.0});
    INFO("eigenvalue " << l << ", closed form " << growth);
    CHECK(std::abs(l.real() - growth) <= 1e-12 * growth);
    CHECK(std::abs(l.imag()) <= 1e-12);
  }
}

TEST_CASE("linearize: a clamped beam's natural frequencies and damping", "[linearize][flexible]") {
  // Euler-Bernoulli cantilever: f_1 = (1.8751^2 / 2 pi) sqrt(EI / (m L^4)); the
  // linear model's frequencies equal the modal data's, damping ratios zeta.
  const std::string yaml = R"(
name: clamped
bodies:
  - name: beam
    parent: ground
    joint: {type: fixed}
    flexible:
      beam: {length: 2.0, direction: x, mass_per_length: 0.5, EI: [40.0, 90.0], elements: 20, modes: 4}
      damping_ratio: 0.02
)";
  const Model model = load_model(test::write_temp("clamped_lin.yaml", yaml));
  auto engine = test::generated_engine(model);
  const LinearModel lin = linearize(*engine, initial_state(model), {});
  CHECK(lin.equilibrium);
  const auto modes = linear_modes(lin);
  REQUIRE(modes.size() == 4);
  const VecX& f = model.bodies[0].flex->frequency_hz;
  for (int k = 0; k < 4; ++k) {
    INFO("mode " << k + 1);
    CHECK(std::abs(modes[k].natural_frequency_hz - f(k)) <= 1e-10 * f(k));
    CHECK(std::abs(modes[k].damping_ratio - 0.02) <= 1e-10);
  }
  // the built-in beam lumps its mass at the nodes (model/beam.hpp): with 20
  // elements its first frequency is 0.11 % above the continuum's
  const double f1 = 1.87510407 * 1.87510407 / (2 * M_PI) * std::sqrt(40.0 / (0.5 * 16.0));
  CHECK(std::abs(modes[0].natural_frequency_hz - f1) <= 2e-3 * f1);
}

TEST_CASE("linearize: exact derivatives agree with central differences", "[linearize][generated]") {
  const Model model = load_model(test::source_path("tests/data/good/gnc_ports.yaml"));
  State s = load_state(model, test::write_temp("lin_state.json", R"({"inputs": {"thr": 2.0, "mtq.x": 0.3,
     "push.y": -2.0, "twist.z": -0.3, "motor": 0.7, "tipload.z": -0.4}, "tau": {"arm.angle": 0.05}})"));
  auto generated = test::generated_engine(model);
  GenericEngine generic(model);
  LinearizeOptions o;
  o.inputs = {"thr", "mtq", "motor", "tau.arm.angle"};
  const LinearModel exact = linearize(*generated, s, o);
  CHECK(exact.method.find("exact") != std::string::npos);
  const LinearModel fd = linearize(generic, s, o);
  CHECK(fd.method.find("central") != std::string::npos);
  REQUIRE(exact.A.rows() == 2 * model.nu);
  REQUIRE(exact.B.cols() == 6);
  // attitude outputs become small rotations: 2 quaternions -> 3 rows each
  CHECK(exact.C.rows() == model.ny - 2);
  CHECK(std::find(exact.output_names.begin(), exact.output_names.end(), "att.rx") != exact.output_names.end());
  for (const char* k : {"A", "B", "C", "D"}) {
    const MatX& a = k[0] == 'A' ? exact.A : k[0] == 'B' ? exact.B : k[0] == 'C' ? exact.C : exact.D;
    const MatX& b = k[0] == 'A' ? fd.A : k[0] == 'B' ? fd.B : k[0] == 'C' ? fd.C : fd.D;
    INFO(k << ": exact vs central differences " << test::rel_err(a, b));
    CHECK(test::rel_err(a, b) <= test::kCentralDifference);
  }
  // the generated engine's own central differences agree too (same code, other method)
  o.finite_differences = true;
  const LinearModel fd_gen = linearize(*generated, s, o);
  CHECK(test::rel_err(fd_gen.A, exact.A) <= test::kCentralDifference);
  CHECK((exact.x0_dot - fd.x0_dot).cwiseAbs().maxCoeff() <= 1e-11 * (1 + fd.x0_dot.cwiseAbs().maxCoeff()));
}

TEST_CASE("linearize: spinning wheels are a relative equilibrium, ignorable coordinates, zero modes, --drop-ignorable",
          "[linearize][generated]") {
  // The slew spacecraft at rest with its three wheels spinning (balanced wheels, no gravity): u_dot = 0,
  // only the wheel angles move; nothing depends on them, nor on the bus position and attitude.
  const Model model = load_model(test::source_path("models/gnc/slew_spacecraft.yaml"));
  auto engine = test::generated_engine(model);
  const State s = at(model, {}, {{"rw_x.angle_rate", 50.0}, {"rw_y.angle_rate", -30.0}, {"rw_z.angle_rate", 80.0}});
  const LinearModel lin = linearize(*engine, s, {});
  CHECK_FALSE(lin.equilibrium);
  CHECK(lin.relative_equilibrium);
  for (const char* q : {"q.rw_x.angle", "q.rw_y.angle", "q.rw_z.angle", "q.bus.x", "q.bus.y", "q.bus.z"})
    CHECK(std::find(lin.ignorable.begin(), lin.ignorable.end(), q) != lin.ignorable.end());
  for (const auto& n : lin.ignorable) CHECK(n.rfind("q.array", 0) != 0);  // the arrays' deflections are not
  const auto modes = linear_modes(lin);
  int zeros = 0;
  for (const auto& m : modes) {
    if (std::abs(m.eigenvalue) < 1e-6) {
      CHECK(m.zero);
      CHECK(std::isnan(m.damping_ratio));
    }
    zeros += m.zero;
  }
  CHECK(zeros >= 6);
  // without the ignorable coordinates: an equilibrium, and the elastic modes unchanged (the others do not depend
  // on what was dropped, so dropping it is exact)
  LinearizeOptions o;
  o.drop_ignorable = true;
  const LinearModel dropped = linearize(*engine, s, o);
  CHECK(dropped.equilibrium);
  // the star tracker reads the bus attitude: those ignorable states stay (C exact), the wheel angles go
  CHECK(dropped.ignorable_kept_for_outputs == std::vector<std::string>{"q.bus.rx", "q.bus.ry", "q.bus.rz"});
  CHECK(dropped.A.rows() == lin.A.rows() - static_cast<Eigen::Index>(lin.ignorable.size() - 3));
  for (const char* q : {"q.rw_x.angle", "q.rw_y.angle", "q.rw_z.angle", "q.bus.x"})
    CHECK(std::find(dropped.state_names.begin(), dropped.state_names.end(), q) == dropped.state_names.end());
  const auto dm = linear_modes(dropped);
  int elastic = 0;
  for (const auto& m : modes) {
    if (m.zero || m.eigenvalue.imag() < 1.0) continue;
    ++elastic;
    const auto l = nearest(dm, m.eigenvalue);
    INFO("elastic mode " << m.eigenvalue << " after dropping " << l);
    CHECK(std::abs(l - m.eigenvalue) <= 1e-9 * std::abs(m.eigenvalue));
    // the arrays' 0.5 % of their clamped modes, shared with the bus in a free spacecraft's mode: near it, positive
    CHECK(m.damping_ratio > 0.002);
    CHECK(m.damping_ratio < 0.02);
  }
  CHECK(elastic >= 6);
}

TEST_CASE("linearize: exact above 6000 u-dot operations (spacecraft_arrays), equal to central differences",
          "[linearize][generated]") {
  // 21 speeds, two hinged flexible wings and a flexible boom: its u-dot is compiled at -O0 and its Jacobian
  // is not used by the implicit integrators (jacobian_for_integration false: above 6000 operations), but
  // linearize still takes the exact derivatives, never finite differences unless asked
  const Model model = load_model(test::source_path("models/spacecraft_arrays.yaml"));
  auto generated = test::generated_engine(model);
  CHECK_FALSE(generated->jacobian_for_integration());
  REQUIRE(generated->has_jacobian());
  const State s = initial_state(model);
  const LinearModel exact = linearize(*generated, s, {});
  CHECK(exact.method.rfind("exact", 0) == 0);
  GenericEngine generic(model);
  const LinearModel fd = linearize(generic, s, {});
  CHECK(fd.method.find("central") != std::string::npos);
  INFO("A: exact vs central differences " << test::rel_err(exact.A, fd.A) << ", B " << test::rel_err(exact.B, fd.B));
  CHECK(test::rel_err(exact.A, fd.A) <= 1e-6);
  CHECK(test::rel_err(exact.B, fd.B) <= 1e-6);
}
