// STATE.json (interface.md) and initial states.
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;
using Catch::Matchers::Contains;

// test_model_loader.cpp: loads tests/reference/<name>/<name>.yaml (a patched
// copy while the reference modal file lacks a shape, see there).
Model load_reference_model(const std::string& name);

namespace {

const std::string kRef = std::string(kanegen::test::source_dir()) + "/tests/reference/";
using test::data_path;

/// Writes `text` to a temporary STATE.json (in this test process's own
/// directory: ctest runs the test cases of this file in parallel) and returns its path.
std::string write_state(const std::string& text, const std::string& name = "kanegen_test_state.json") {
  return test::write_temp(name, text);
}

std::vector<Diagnostic> refusal(const Model& m, const std::string& path) {
  try {
    load_state(m, path);
  } catch (const InputError& e) {
    return e.diagnostics();
  }
  FAIL("state was accepted: " << path);
  return {};
}

using test::dump;

}  // namespace

TEST_CASE("state: reference states load in model order, quaternions normalized", "[state]") {
  for (const char* name : {"v_double3d", "v_prismatic_chain", "v_branched", "v_free_appendages", "v_free_child",
                           "v_flex", "v_flex_free"}) {
    INFO(name);
    const std::string dir = kRef + name + "/";
    const Model m = load_reference_model(name);
    for (const char* st : {"state1", "state2"}) {
      const State s = load_state(m, dir + st + ".json");
      std::ifstream fe(dir + st + ".expected.json");
      const auto e = nlohmann::json::parse(fe);
      std::ifstream fi(dir + st + ".json");
      const auto in = nlohmann::json::parse(fi);
      const auto q = e["q"].get<std::vector<double>>();
      const auto u = e["u"].get<std::vector<double>>();
      REQUIRE(static_cast<int>(q.size()) == m.nq);
      REQUIRE(static_cast<int>(u.size()) == m.nu);
      for (int i = 0; i < m.nq; ++i) CHECK(s.q(i) == Approx(q[i]).epsilon(1e-15).margin(1e-300));
      for (int i = 0; i < m.nu; ++i) CHECK(s.u(i) == u[i]);
      for (const auto& [k, v] : in["tau"].items()) CHECK(s.tau(m.speed_index(k)) == v.get<double>());  // older names
      CHECK(s.t == in["t"].get<double>());
    }
  }
}

TEST_CASE("state: names not given take the model's initial value, tau 0", "[state]") {
  const Model m = load_model(data_path("good/initial.yaml"));
  const State s0 = initial_state(m);
  CHECK(s0.q == m.q0);
  CHECK(s0.u == m.u0);
  CHECK(s0.tau.size() == m.nu);
  CHECK(s0.tau.isZero(0.0));
  CHECK(s0.t == 0.0);

  const State s = load_state(m, write_state(R"({"t": 2.5, "q": {"a.angle": -1.0, "rotor.qw": 0, "rotor.qx": 0,
      "rotor.qy": 3, "rotor.qz": 4}, "tau": {"b.disp": 0.7}})"));
  CHECK(s.t == 2.5);
  CHECK(s.q(m.q_index("a.angle")) == -1.0);
  CHECK(s.q(m.q_index("bus.x")) == 1.5);  // from initial:
  CHECK(s.q(m.q_index("bus.qw")) == m.q0(m.q_index("bus.qw")));
  CHECK(s.q(m.q_index("rotor.qy")) == Approx(0.6).epsilon(1e-15));  // any non-zero norm normalized
  CHECK(s.q(m.q_index("rotor.qz")) == Approx(0.8).epsilon(1e-15));
  CHECK(s.u == m.u0);
  CHECK(s.tau(m.u_index("b.disp_rate")) == 0.7);
  CHECK(s.tau(m.u_index("a.angle_rate")) == 0.0);
}

TEST_CASE("state: unknown names refused with the field", "[state]") {
  const Model m = load_model(kRef + "v_double3d/v_double3d.yaml");
  const std::string p = write_state(R"({"q": {"link9.angle": 0.1}, "u": {"link1.angle": 1}, "tau": {"link1.disp": 1}})");
  const auto ds = refusal(m, p);
  INFO(dump(ds));
  REQUIRE(ds.size() == 2);
  CHECK(ds[0].file == p);
  CHECK(ds[0].field == "q.link9.angle");
  CHECK_THAT(ds[0].message, Contains("unknown name"));
  CHECK(ds[1].field == "tau.link1.disp");
  CHECK_THAT(ds[1].message, Contains("link1.angle"));
}

TEST_CASE("state: quaternion given in part, zero quaternion", "[state]") {
  const Model m = load_model(kRef + "v_free_child/v_free_child.yaml");
  {
    const auto ds = refusal(m, write_state(R"({"q": {"pod.qw": 1.0, "pod.qz": 0.0}})"));
    INFO(dump(ds));
    REQUIRE(ds.size() == 1);
    CHECK(ds[0].field == "q.pod.qw");
    CHECK_THAT(ds[0].message, Contains("given in part"));
  }
  {
    const auto ds = refusal(m, write_state(R"({"q": {"pod.qw": 0, "pod.qx": 0, "pod.qy": 0, "pod.qz": 0}})"));
    INFO(dump(ds));
    REQUIRE(ds.size() == 1);
    CHECK(ds[0].field == "q.pod.qw");
    CHECK_THAT(ds[0].message, Contains("zero"));
  }
}

TEST_CASE("state: non-numbers, unknown keys, bad JSON, missing file", "[state]") {
  const Model m = load_model(kRef + "v_double3d/v_double3d.yaml");
  {
    const auto ds = refusal(m, write_state(R"({"t": "now", "q": {"link1.angle": "0.1"}, "u": [1, 2], "extra": 1})"));
    INFO(dump(ds));
    REQUIRE(ds.size() == 4);
    auto has = [&](const std::string& f) {
      return std::any_of(ds.begin(), ds.end(), [&](const Diagnostic& d) { return d.field == f; });
    };
    CHECK(has("t"));
    CHECK(has("q.link1.angle"));
    CHECK(has("u"));
    CHECK(has("extra"));
  }
  {
    const std::string p = write_state("{\"t\": 0,\n \"q\": {\"link1.angle\": 0.1,}\n}");
    const auto ds = refusal(m, p);
    INFO(dump(ds));
    REQUIRE(ds.size() == 1);
    CHECK(ds[0].file == p);
    CHECK(ds[0].line == 2);
    CHECK_THAT(ds[0].message, Contains("malformed JSON"));
  }
  {
    const std::string p = data_path("no_such_state.json");
    const auto ds = refusal(m, p);
    REQUIRE(ds.size() == 1);
    CHECK(ds[0].file == p);
    CHECK_THAT(ds[0].message, Contains("cannot open"));
  }
}
