// Compact u-dot code (codegen/outlined_code.hpp, issue 38): kernels shared by
// the bodies whose code has the same shape. The same operations as the
// straight-line code, so the same u-dot to rounding, on chains, trees,
// flexible bodies, free roots in orbit and prescribed motion; the kernels do
// not grow with the chain; the cost model's choice ("auto") is what docs/speed.md measured.
#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <cmath>
#include <random>

#include "codegen/generator.hpp"
#include "codegen/jit_generator.hpp"
#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "sim/crosscheck.hpp"
#include "tests/support/random_chain.hpp"
#include "tests/support/crosscheck_checks.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

std::unique_ptr<GeneratedEngine> engine_with(const Model& model, const std::string& code, const std::string& form) {
  codegen::GeneratorOptions g;
  g.udot_code = code;
  g.udot_form = form;
  return jit_load(model, codegen::jit_code_generator(g), test::jit_options());
}

const codegen::EmittedFunction& udot_of(const codegen::EmittedModel& m) {
  const codegen::EmittedFunction* f = m.find("udot");
  REQUIRE(f != nullptr);
  return *f;
}

}  // namespace

TEST_CASE("compact u-dot code: a chain's middle links share kernels, which do not grow with the chain",
          "[generator][compact]") {
  codegen::GeneratorOptions compact;
  compact.udot_code = "compact";
  compact.udot_form = "articulated";
  std::vector<long> kernel_ops;
  for (int n : {8, 16, 24}) {
    INFO(n << " links");
    const Model model = load_model(test::write_temp(fmt::format("compact_chain{}.yaml", n), test::random_chain(n, 7)));
    const codegen::EmittedModel straight_model = codegen::generate(model, [] {
      codegen::GeneratorOptions o;
      o.udot_code = "straight-line";
      o.udot_form = "articulated";
      return o;
    }());
    const codegen::EmittedFunction& straight = udot_of(straight_model);
    const codegen::EmittedModel compact_model = codegen::generate(model, compact);
    const codegen::EmittedFunction& f = udot_of(compact_model);
    CHECK(straight.kernels.empty());
    REQUIRE(!f.kernels.empty());
    // the same operations, every call counted; three groups per body (outward velocities and forces, inward
    // articulated inertias, outward accelerations), the leaf's first two fused and the base's last two
    CHECK(f.ops.total() == straight.ops.total());
    CHECK(f.kernel_calls == 3 * n - 2);
    // the kernels: the base's, the first links', the middle links' (one per pass), the leaf's; their code is
    // the same for 8, 16 and 24 links
    CHECK(f.kernels.size() <= 12);
    kernel_ops.push_back(f.kernel_ops.total());
    // (their code is a fixed ~1,500 operations: over half an 8-link chain's 2,950, a sixth of 24 links')
    CHECK(f.kernel_ops.total() < (n >= 16 ? 0.3 : 0.6) * f.ops.total());
    // every body's values at like offsets in its region of the workspace: each kernel addresses every value it
    // reads or writes by a constant offset from its call's region, none through a table
    for (const std::string& k : f.kernels) CHECK(k.find("w[x[") == std::string::npos);
    CHECK(f.kernel_tables.find("static constexpr int") == std::string::npos);
  }
  // (a random constant that folds to 0 or 1 may change a kernel by an operation)
  CHECK(std::abs(kernel_ops[1] - kernel_ops[0]) <= 0.01 * kernel_ops[0]);
  CHECK(std::abs(kernel_ops[2] - kernel_ops[0]) <= 0.01 * kernel_ops[0]);
}

TEST_CASE("compact u-dot code computes the straight-line code's u-dot and Jacobian, chains, trees, flexible "
          "bodies and free roots in orbit",
          "[generator][compact][jit]") {
  struct Case {
    std::string name, path, form;
  };
  const std::string chain = test::write_temp("compact_chain12.yaml", test::random_chain(12, 11));
  const std::vector<Case> cases = {
      {"random 12-link chain, articulated", chain, "articulated"},
      {"random 12-link chain, composite", chain, "composite"},
      {"branched tree", test::source_path("models/branched_tree.yaml"), "articulated"},
      {"random 15-body tree (screw turns to its other children), composite",
       test::write_temp("compact_tree15.yaml", test::random_tree(15, 4)), "composite"},
      {"flexible spacecraft (modes, wheels, a gimbal)", test::source_path("models/flexible_spacecraft.yaml"), "auto"},
      {"Explorer I in orbit (central gravity, free root)", test::source_path("models/explorer1_orbit.yaml"), "auto"},
      {"prescribed motion (a polynomial and a sine: time-dependent code and its preludes)",
       test::source_path("tests/reference/v_prescribed_mix/v_prescribed_mix.yaml"), "composite"},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    const Model model = load_model(c.path);
    // (for the models whose "auto" code is straight-line, the suite's own build of it)
    auto straight = c.form == "auto" ? test::generated_engine(model) : engine_with(model, "straight-line", c.form);
    if (c.form == "auto") REQUIRE(codegen::generate(model).find("udot")->kernels.empty());
    auto compact = engine_with(model, "compact", c.form);
    {
      // the workspace's regions: like bodies' at one stride, but never more than a third of it gaps (the
      // flexible spacecraft's flexible body, with far more values than its rigid wheels, would take over three
      // times its values at one stride)
      codegen::GeneratorOptions g;
      g.udot_code = "compact";
      g.udot_form = c.form;
      const codegen::EmittedModel m = codegen::generate(model, g);
      const codegen::EmittedFunction& f = udot_of(m);
      CHECK(f.workspace_values > 0);
      CHECK(f.workspace <= f.workspace_values + f.workspace_values / 2 + 64);
    }
    GenericEngine generic(model);
    // against the straight-line code: the same operations, the order of commutative operands aside
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    for (int k = 0; k < 4; ++k) {
      State x = initial_state(model);
      for (int i = 0; i < model.nu; ++i) x.u(i) += 0.5 * U(rng);
      VecX a, b;
      straight->udot(x.q, x.u, x.tau, a);
      compact->udot(x.q, x.u, x.tau, b);
      CHECK(test::rel_err(b, a) <= 1e-13);
      MatX Ja, Jb;
      REQUIRE(straight->jacobian(x.t, x.q, x.u, x.tau, Ja));
      REQUIRE(compact->jacobian(x.t, x.q, x.u, x.tau, Jb));
      CHECK(test::rel_err(Jb, Ja) <= 1e-12);
    }
    // against the generic engine, as every model's generated code is (it sets random inputs on both: last)
    const CrosscheckResult r = crosscheck(*compact, generic, 4, 5);
    test::check_within_tolerances(r);
  }
}

TEST_CASE("compact u-dot code: the cost model's choice", "[generator][compact]") {
  // auto: compact for a long chain (beyond the instruction cache, its bodies share kernels), straight-line for
  // a short one and for the flexible spacecraft (its bodies share nothing)
  const Model long_chain = load_model(test::write_temp("compact_chain20.yaml", test::random_chain(20, 5)));
  const Model short_chain = load_model(test::write_temp("compact_chain4.yaml", test::random_chain(4, 5)));
  const Model flexible = load_model(test::source_path("models/flexible_spacecraft.yaml"));
  CHECK_FALSE(udot_of(codegen::generate(long_chain)).kernels.empty());
  CHECK(udot_of(codegen::generate(short_chain)).kernels.empty());
  const codegen::EmittedFunction& f = udot_of(codegen::generate(flexible));
  CHECK(f.ops.total() > codegen::kCompactAboveOps);
  CHECK(f.kernels.empty());
}
