// simulate() at its edges: a model without degrees of freedom.
#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>

#include "engine/generic_engine.hpp"
#include "model/model_loader.hpp"
#include "model/state_io.hpp"
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
