// Runtime parameters (model/parameters.hpp, docs/sweeps.md): the generated
// code evaluated at changed parameter values equals the generic engine on the
// model changed in its file; the JIT reuses one library for any values.
#include <catch2/catch.hpp>

#include <fstream>
#include <random>
#include <sstream>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/parameters.hpp"
#include "sim/crosscheck.hpp"
#include "tests/support/crosscheck_checks.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const char* kParameters = R"(
parameters: [bus.mass, bus.com, bus.inertia, tracker.mass, tracker.inertia.xy, arm.stiffness, arm.damping, arm.rest,
             arm.com.x, boom.frequency, boom.damping_ratio2, gravity, tracker.misalignment, arm.position,
             arm.misalignment.z, boom.position.y]
)";

}  // namespace

TEST_CASE("runtime parameters: generated at changed values equals generic on the changed model", "[parameters][generated]") {
  const std::string base = read(test::source_path("tests/data/good/gnc_ports.yaml"));
  const Model model = load_model(test::write_temp("params.yaml", base + kParameters));
  REQUIRE(model.parameters.size() == 1 + 3 + 6 + 1 + 1 + 3 + 1 + 3 + 1 + 3 + 3 + 3 + 1 + 1);
  auto generated = test::generated_engine(model);
  GenericEngine generic(model);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0.8, 1.25);
  for (int trial = 0; trial < 3; ++trial) {
    VecX p = Engine::nominal_parameters(model);
    for (Eigen::Index k = 0; k < p.size(); ++k) {
      const RuntimeParameter& rp = model.parameters[static_cast<std::size_t>(k)];
      // scale every value; off-diagonal inertia and com components by less, to stay physical
      if (rp.kind == ParameterKind::misalignment)
        p(k) = 0.02 * (U(rng) - 1.0);  // a few milliradians to a degree
      else
        p(k) = rp.kind == ParameterKind::inertia && rp.index >= 3 ? p(k) * 0.5 : p(k) * U(rng) + (p(k) == 0 ? 0.05 : 0.0);
    }
    INFO("trial " << trial);
    generated->set_parameters(p);
    generic.set_parameters(p);
    // the model changed in place (as a new file would be): its own generic engine
    Model changed = model;
    apply_parameters(changed, model.parameters, p);
    changed.parameters.clear();
    GenericEngine reference(changed);
    for (Engine* e : {static_cast<Engine*>(generated.get()), static_cast<Engine*>(&generic)}) {
      INFO(e->name());
      const CrosscheckResult r = crosscheck(*e, reference, 5, 100 + trial);
      test::check_within_tolerances(r);
    }
    // the values matter: the nominal model differs
    VecX ud_nominal, ud_changed;
    GenericEngine nominal(model);
    nominal.udot(model.q0, model.u0, VecX::Zero(model.nu), ud_nominal);
    generated->udot(model.q0, model.u0, VecX::Zero(model.nu), ud_changed);
    CHECK(test::rel_err(ud_changed, ud_nominal) > 1e-3);
  }
  // out-of-domain values are refused and leave the engine as it was
  VecX bad = generated->parameters();
  bad(0) = -1.0;  // bus.mass
  CHECK_THROWS_AS(generated->set_parameters(bad), std::invalid_argument);
  CHECK(generated->parameters()(0) > 0);
}

TEST_CASE("runtime parameters: one compiled library for any values", "[parameters][jit]") {
  const std::string base = read(test::source_path("tests/data/good/gnc_ports.yaml"));
  const Model a = load_model(test::write_temp("params_a.yaml", base + kParameters));
  // the same model with other nominal values of its runtime parameters (and the same otherwise)
  std::string other = base;
  other.replace(other.find("mass: 50.0"), 10, "mass: 65.0");
  const Model b = load_model(test::write_temp("params_b.yaml", other + kParameters));
  auto ea = test::generated_engine(a);
  auto eb = test::generated_engine(b);
  CHECK(ea->library_path() == eb->library_path());
  // a different set of runtime parameters is other code
  const Model c = load_model(test::write_temp("params_c.yaml", base + "\nparameters: [bus.mass]\n"));
  CHECK(test::generated_engine(c)->library_path() != ea->library_path());
  // b's code evaluates b's values (not a's nominal ones)
  GenericEngine gb(b);
  const CrosscheckResult r = crosscheck(*eb, gb, 3, 3);
  CHECK(r.passed());
}

TEST_CASE("runtime parameters: the rigid part of a flexible body whose nodes foreshorten", "[parameters][generated]") {
  // the wing's nodes carry second-order shapes, so the generator forms their sums once per body
  // (model/modal_integrals.hpp: RichNodeSums) beside the rigid part it reads from the parameters
  const std::string base = read(test::source_path("models/extreme/many_modes_short_beam.yaml"));
  const Model model =
      load_model(test::write_temp("params_rich.yaml", base + "\nparameters: [wing.mass, wing.com, wing.inertia]\n"));
  REQUIRE(model.bodies[1].flex);
  bool rich = false;
  for (std::size_t k = 0; k < model.bodies[1].flex->nodes.size(); ++k)
    rich = rich || model.bodies[1].flex->has_second_order(static_cast<int>(k));
  REQUIRE(rich);
  auto generated = test::generated_engine(model);
  VecX p = Engine::nominal_parameters(model);
  // mass, com, inertia (xx yy zz xy xz yz about the com) changed well away from nominal
  p(0) *= 1.7, p(1) += 0.04, p(2) -= 0.1, p(3) += 0.03;
  p(4) *= 3.0, p(5) *= 1.05, p(6) *= 1.07, p(7) = 0.02, p(8) = -0.01, p(9) = 0.015;
  test::check_within_tolerances(test::crosscheck_at_parameters(*generated, model, p, 5, 41));
  // the values matter
  VecX ud_nominal, ud_changed;
  GenericEngine(model).udot(model.q0, model.u0, VecX::Zero(model.nu), ud_nominal);
  generated->udot(model.q0, model.u0, VecX::Zero(model.nu), ud_changed);
  CHECK(test::rel_err(ud_changed, ud_nominal) > 1e-3);
}
