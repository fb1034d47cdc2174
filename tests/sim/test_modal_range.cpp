// A run reports a flexible body deflected beyond the linear range
// (sim/modal_range.hpp): the clamped beam started in its first mode, undamped
// and without foreshortening, oscillates as eta1(t) = eta1(0) cos(w t), so the
// largest deflection of the run is max_k |Phi_k1| eta1(0), at t = 0 and at the
// tip; above a tenth of the beam's length the run says so, below it nothing.
#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "sim/modal_range.hpp"
#include "sim/row_sink.hpp"
#include "sim/simulate.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

Model beam(double eta1) {
  return load_model(test::write_temp("modal_range_beam.yaml", R"(name: modal_range_beam
gravity: [0, 0, 0]
bodies:
  - name: beam
    parent: ground
    joint: {type: fixed}
    flexible:
      beam: {length: 1.0, direction: x, mass_per_length: 0.5, EI: [20.0, 30.0], elements: 20, modes: 4}
      foreshortening: false
      damping_ratio: 0.0
initial:
  q: {beam.eta1: )" + std::to_string(eta1) + "}\n"));
}

SimulationResult run(const Model& model) {
  GenericEngine engine(model);
  SimulationOptions o;
  o.t_end = 0.2;
  o.dt_out = 0.01;
  RowTable rows;
  return simulate(engine, initial_state(model), o, rows);
}

}  // namespace

TEST_CASE("a flexible body deflected beyond a tenth of its extent is reported with the node, time and size",
          "[flexible][simulate]") {
  const Model small = beam(0.01), large = beam(0.1);
  const FlexibleData& f = *large.bodies[0].flex;
  double tip = 0;  // max_k |Phi_k1|: the first mode's largest node displacement per unit eta1
  for (int k = 0; k < static_cast<int>(f.nodes.size()); ++k) tip = std::max(tip, f.Phi.block<3, 1>(3 * k, 0).norm());
  INFO("max |Phi_k1| = " << tip << " m");
  REQUIRE(0.01 * tip < 0.1);  // the small start stays inside the linear range, the large one leaves it
  REQUIRE(0.1 * tip > 0.1);

  ModalRange range(large);
  range.add(0.0, large.q0);
  REQUIRE(range.excursions().size() == 1);
  const ModalExcursion& e = range.excursions()[0];
  CHECK(e.extent_m == Approx(1.0).epsilon(1e-14));
  CHECK(e.deflection_m == Approx(0.1 * tip).epsilon(1e-14));
  CHECK(e.node_id == f.nodes.back().id);  // the tip

  const SimulationResult r_small = run(small), r_large = run(large);
  CHECK(r_small.quality.warnings.empty());
  REQUIRE(r_large.quality.warnings.size() == 1);
  const std::string& w = r_large.quality.warnings[0];
  INFO(w);
  CHECK(w.find("beam's modal deflection reached") != std::string::npos);
  CHECK(w.find(fmt::format("{:.3g} m", 0.1 * tip)) != std::string::npos);  // at t = 0: cos(w t) <= 1 afterwards
  CHECK(w.find("t = 0 s") != std::string::npos);
}
