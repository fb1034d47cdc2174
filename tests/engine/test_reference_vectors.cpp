// The seven reference models of ../shared/reference (copied to
// tests/reference): `eval` must reproduce the independent answers, matched by
// name. Each quantity is compared relative to its largest entry; u-dot by the
// residual |M u_dot - F| / (|M||u_dot| + |F|), since its forward error grows
// with cond(M) (reference README).
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "sim/eval_report.hpp"
#include "engine/generic_engine.hpp"
#include "engine/jit.hpp"
#include "engine/load_model.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;
using nlohmann::json;

namespace {

Eigen::VectorXd vec(const json& j) {
  Eigen::VectorXd v(j.size());
  for (std::size_t i = 0; i < j.size(); ++i) v(i) = j[i].get<double>();
  return v;
}

/// Entries of `got` (named got_names) reordered to `names`.
Eigen::VectorXd reorder(const json& got, const json& got_names, const json& names) {
  Eigen::VectorXd v(names.size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    auto it = std::find(got_names.begin(), got_names.end(), names[i]);
    REQUIRE(it != got_names.end());
    v(i) = got[it - got_names.begin()].get<double>();
  }
  return v;
}

void check_case(const std::filesystem::path& model_path, const std::filesystem::path& state_path,
                const std::string& engine_name) {
  const std::filesystem::path expected_path =
      state_path.parent_path() / (state_path.stem().string() + ".expected.json");
  INFO(state_path.string());
  const Model model = load_model(model_path.string());
  const State state = load_state(model, state_path.string());
  std::unique_ptr<Engine> engine;
  if (engine_name == "generic")
    engine = std::make_unique<GenericEngine>(model);
  else
    engine = test::generated_engine(model);
  const json got = json::parse(eval_report(*engine, state).dump());
  CHECK(got["engine"] == engine_name);
  json exp;
  std::ifstream(expected_path) >> exp;

  // The reference vectors keep the speed names of before 2026-12-01 (a rate
  // under its coordinate's name): each is translated to the name eval prints now.
  const json& qn = exp["q_names"];
  json un = json::array();
  for (const auto& n : exp["u_names"]) {
    const int k = model.speed_index(n.get<std::string>());
    REQUIRE(k >= 0);
    un.push_back(model.u_names[k]);
  }
  CHECK(test::rel_err(reorder(got["q"], got["q_names"], qn), vec(exp["q"])) < 1e-15);
  CHECK(test::rel_err(reorder(got["qdot"], got["q_names"], qn), vec(exp["qdot"])) < test::kRoundoff);

  // M by name: got row/col index of each expected speed name.
  std::vector<int> idx;
  for (const auto& n : un) idx.push_back(int(std::find(got["u_names"].begin(), got["u_names"].end(), n) - got["u_names"].begin()));
  const int n = static_cast<int>(un.size());
  Eigen::MatrixXd M(n, n), Me(n, n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      M(r, c) = got["M"][idx[r]][idx[c]].get<double>();
      Me(r, c) = exp["M"][r][c].get<double>();
    }
  CHECK(test::rel_err(M, Me) < test::kRoundoff);
  const Eigen::VectorXd F = reorder(got["F"], got["u_names"], un), Fe = vec(exp["F"]);
  CHECK(test::rel_err(F, Fe) < test::kRoundoff);
  const Eigen::VectorXd udot = reorder(got["udot"], got["u_names"], un);
  CHECK((Me * udot - Fe).norm() / (Me.norm() * udot.norm() + Fe.norm()) < test::kRoundoff);

  if (exp.contains("energy")) {
    REQUIRE(got.contains("energy"));
    const Eigen::Vector2d E(got["energy"]["T"], got["energy"]["V"]), Ee(exp["energy"]["T"], exp["energy"]["V"]);
    CHECK(test::rel_err(E, Ee) < test::kRoundoff);
  }
  if (exp.contains("momentum")) {
    REQUIRE(got.contains("momentum"));
    CHECK(test::rel_err(vec(got["momentum"]["p"]), vec(exp["momentum"]["p"]), 1e-12) < test::kRoundoff);
    CHECK(test::rel_err(vec(got["momentum"]["H"]), vec(exp["momentum"]["H"]), 1e-12) < test::kRoundoff);
  }
  if (exp.contains("reactions")) {
    REQUIRE(got.contains("reactions"));
    for (const auto& [body, r] : exp["reactions"].items()) {
      INFO("reaction on " << body);
      REQUIRE(got["reactions"].contains(body));
      Eigen::VectorXd w(6), we(6);
      w << vec(got["reactions"][body]["force"]), vec(got["reactions"][body]["torque"]);
      we << vec(r["force"]), vec(r["torque"]);
      // Reactions subtract large inertia and gravity terms: relative to their own scale
      CHECK(test::rel_err(w, we, 1e-12) < 1e-11);
    }
  }
}

}  // namespace

void check_all(const std::string& engine_name) {
  const std::filesystem::path root = test::source_path("tests/reference");
  int cases = 0;
  for (const auto& dir : std::filesystem::directory_iterator(root)) {
    if (!dir.is_directory()) continue;
    const auto model_path = dir.path() / (dir.path().filename().string() + ".yaml");
    for (int k = 1; k <= 2; ++k) {
      const auto state_path = dir.path() / ("state" + std::to_string(k) + ".json");
      if (!std::filesystem::exists(state_path)) continue;
      SECTION(dir.path().filename().string() + " state" + std::to_string(k)) {
        check_case(model_path, state_path, engine_name);
      }
      ++cases;
    }
  }
  CHECK(cases == 18);
}

TEST_CASE("generic engine reproduces every reference vector", "[reference][generic]") { check_all("generic"); }

// Hidden ([.]): ctest runs it after the fixtures that build the reference models' code (tests/CMakeLists.txt).
TEST_CASE("generated engine reproduces every reference vector", "[.][reference][generated]") { check_all("generated"); }
