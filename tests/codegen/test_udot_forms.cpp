// The generator's two u-dot forms (composite inertia + tree LTDL, and the
// articulated-body recursion) on every model, flexible ones included: both
// agree with the generic engine, whichever the generator would pick. And
// what each form reports when M is singular: the speed whose pivot failed.
#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <filesystem>
#include <fstream>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "sim/crosscheck.hpp"
#include "tests/support/crosscheck_checks.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;
namespace fs = std::filesystem;

namespace {

}  // namespace

// Hidden ([.]): ctest runs it once per model ("u-dot forms: <model>",
// tests/CMakeLists.txt); the test below checks that those cover every model.
TEST_CASE("both u-dot forms agree with the generic engine on every model", "[.][generator][forms][per-model]") {
  for (const auto& f : test::models_under_test(test::all_models())) {
    const Model model = load_model(f);
    GenericEngine generic(model);
    const auto engines = test::generated_engines_in_both_forms(model);
    REQUIRE(engines.size() == 2);
    for (const auto& e : engines) {
      INFO(fs::path(f).filename().string() << " " << e->udot_form());
      const CrosscheckResult r = crosscheck(*e, generic, 4, 11);
      test::check_within_tolerances(r);
    }
    CHECK(engines[0]->udot_form() != engines[1]->udot_form());  // one of each
  }
}

TEST_CASE("the per-model tests run on every model, flexible ones and node children among them", "[generator][forms]") {
  const auto files = test::all_models();
  REQUIRE(files.size() >= 20);
  int flexible = 0, node_children = 0;
  for (const auto& f : files) {
    const Model model = load_model(f);
    flexible += model.has_flexible();
    for (const Body& b : model.bodies) node_children += b.joint.node >= 0;
  }
  // The modal and node-attachment branches of both forms are exercised.
  CHECK(flexible >= 5);
  CHECK(node_children >= 3);
  // ctest holds one entry per model and per every-model test (the list CMake
  // wrote when it made them): none left out, none stale
  std::ifstream listed(kanegen::test::per_model_list());
  REQUIRE(listed);
  std::vector<std::string> names;
  for (std::string line; std::getline(listed, line);)
    if (!line.empty()) names.push_back(test::source_path(line));
  std::sort(names.begin(), names.end());
  CHECK(names == files);
}

TEST_CASE("jit: the suite's build of a model in every u-dot form", "[.][jit][per-model]") {
  // ctest's fixture "jit: <model>": builds the code every test of the model loads, each form once
  for (const auto& f : test::models_under_test(test::all_models())) {
    const Model model = load_model(f);
    CHECK(test::generated_engines_in_both_forms(model).size() == 2);
  }
}

TEST_CASE("a singular mass matrix names the speed whose pivot failed, in both forms", "[generator][forms]") {
  // root -- mid -- leaf, revolute joints; the leaf's mass is on its own axis
  // and its inertia about that axis is negative (not physical: a programmatic
  // model that the loader would refuse, so that the pivot of the leaf's speed,
  // and only that one, fails in both factorizations; a zero inertia would be
  // folded away by the generator).
  Model m;
  m.name = "singular_leaf";
  for (int i = 0; i < 3; ++i) {
    Body b;
    b.name = i == 0 ? "root" : i == 1 ? "mid" : "leaf";
    b.parent = i - 1;
    b.joint.type = JointType::revolute;
    b.joint.axis_J = i == 1 ? Vec3::UnitY() : Vec3::UnitZ();
    b.joint.p_PJ = i == 0 ? Vec3::Zero() : Vec3(1, 0, 0);
    b.rigid.mass = 1.0;
    if (i < 2) {
      b.rigid.com_B = Vec3(0.5, 0, 0);
      b.rigid.I_c_B = Vec3(0.01, 0.1, 0.1).asDiagonal();
    } else {
      b.rigid.I_c_B = Vec3(0.01, 0.01, -0.001).asDiagonal();
    }
    m.bodies.push_back(b);
  }
  finalize_model(m);
  const State s = initial_state(m);
  VecX ud;
  GenericEngine generic(m);
  CHECK_THROWS_AS(generic.udot(s.q, s.u, s.tau, ud), SingularMassMatrix);
  for (const char* form : {"composite", "articulated"}) {
    INFO(form);
    auto e = test::generated_engine(m, form);
    try {
      e->udot(s.q, s.u, s.tau, ud);
      FAIL("no SingularMassMatrix");
    } catch (const SingularMassMatrix& err) {
      CHECK(err.speed == m.u_index("leaf.angle_rate"));
      CHECK(std::string(err.what()).find("'leaf.angle_rate'") != std::string::npos);
    }
  }
}

TEST_CASE("model names that are C++ keywords or start with a digit generate code that compiles", "[generator]") {
  const std::string body = "bodies:\n  - name: arm\n    parent: ground\n    joint: {type: revolute, axis: [0, 1, 0]}\n"
                           "    mass: 1.0\n    com: [0.5, 0, 0]\n    inertia: [0.01, 0.02, 0.02, 0, 0, 0]\n"
                           "gravity: [0, 0, -9.81]\n";
  for (const std::string name : {"int", "class", "9lives", "namespace", "std"}) {
    INFO(name);
    const std::string path = test::write_temp(name + ".yaml", "name: " + name + "\n" + body);
    const Model model = load_model(path);
    auto e = test::generated_engine(model, "auto");
    GenericEngine generic(model);
    const CrosscheckResult r = crosscheck(*e, generic, 2, 3);
    CHECK(r.passed());
    CHECK(std::string(e->api().model_name) == name);  // the user's name stays in strings
  }
}
