// The generated engine against the generic one and against itself: random-
// state cross-checks on every model of models/, the exact Jacobian against
// finite differences, the Jacobian's use by CVODE, and the ahead-of-time
// simulator built by kanegen_add_model.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include "sim/crosscheck.hpp"
#include "engine/generic_engine.hpp"
#include "engine/jit.hpp"
#include "engine/load_model.hpp"
#include "sim/simulate.hpp"
#include "model/state_io.hpp"
#include "tests/support/crosscheck_checks.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;
namespace fs = std::filesystem;

// Hidden ([.]): ctest runs it once per model ("crosscheck: <model>", tests/CMakeLists.txt).
TEST_CASE("crosscheck: generated agrees with generic on every model", "[.][crosscheck][generated][per-model]") {
  for (const fs::path f : test::models_under_test(test::model_files())) {
    if (f.string().find("/extreme/") != std::string::npos) continue;  // checked by the extreme suite
    INFO(f.filename().string());
    const Model model = load_model(f.string());
    auto generated = test::generated_engine(model);
    GenericEngine generic(model);
    const CrosscheckResult r = crosscheck(*generated, generic, 10, 7);
    test::check_within_tolerances(r);
    CHECK(r.passed());
  }
}

TEST_CASE("generated Jacobian matches central finite differences", "[jacobian][generated]") {
  for (const char* rel : {"models/double_pendulum.yaml", "tests/reference/v_flex_free/v_flex_free.yaml",
                          "tests/reference/v_free_child/v_free_child.yaml"}) {
    INFO(rel);
    const Model model = load_model(test::source_path(rel));
    auto engine = test::generated_engine(model);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> U(-1, 1);
    State s = initial_state(model);
    for (int i = 0; i < model.nq; ++i) s.q(i) += 0.2 * U(rng);
    for (const Body& b : model.bodies)
      if (b.joint.type == JointType::free) s.q.segment<4>(b.q_joint + 3).normalize();
    for (int i = 0; i < model.nu; ++i) s.u(i) = U(rng), s.tau(i) = 0.3 * U(rng);
    const int nq = model.nq, nu = model.nu, nx = nq + nu;
    MatX J;
    REQUIRE(engine->jacobian(s.q, s.u, s.tau, J));
    REQUIRE(J.rows() == nx);
    auto f = [&](const VecX& x) {
      VecX qd, ud, out(nx);
      engine->qdot(x.head(nq), x.tail(nu), qd);
      engine->udot(x.head(nq), x.tail(nu), s.tau, ud);
      out << qd, ud;
      return out;
    };
    VecX x(nx);
    x << s.q, s.u;
    MatX Jfd(nx, nx);
    for (int c = 0; c < nx; ++c) {
      const double h = 1e-6 * std::max(1.0, std::abs(x(c)));
      VecX xp = x, xm = x;
      xp(c) += h;
      xm(c) -= h;
      Jfd.col(c) = (f(xp) - f(xm)) / (2 * h);
    }
    // Central differences carry O(h^2) truncation and O(eps/h) rounding errors: ~1e-9 relative.
    CHECK(test::rel_err(J, Jfd) < 1e-7);
  }
}

TEST_CASE("CVODE BDF with the generated Jacobian: same answer, fewer RHS evaluations", "[jacobian][generated]") {
  const Model model = load_model(test::source_path("models/chain5_prismatic.yaml"));
  auto engine = test::generated_engine(model);
  const State s0 = initial_state(model);
  SimulationOptions opt;
  opt.t_end = 5.0;
  opt.dt_out = 5.0;
  opt.integrator.kind = IntegratorKind::cvode_bdf;
  opt.integrator.rtol = 1e-10;
  opt.integrator.atol = 1e-12;
  std::ostringstream a, b;
  opt.use_jacobian = true;
  const SimulationResult with = simulate(*engine, s0, opt, a);
  opt.use_jacobian = false;
  const SimulationResult without = simulate(*engine, s0, opt, b);
  INFO("with J: " << with.stats.summary() << "; finite differences: " << without.stats.summary());
  CHECK(with.stats.jac_evals > 0);
  CHECK(with.stats.rhs_evals < without.stats.rhs_evals);
  // Final states agree to the integration tolerance.
  auto last_row = [](const std::string& csv) {
    std::istringstream in(csv);
    std::string line, last;
    while (std::getline(in, line))
      if (!line.empty()) last = line;
    std::vector<double> v;
    std::stringstream ss(last);
    for (std::string t; std::getline(ss, t, ',');) v.push_back(std::stod(t));
    return v;
  };
  const auto ra = last_row(a.str()), rb = last_row(b.str());
  REQUIRE(ra.size() == rb.size());
  for (std::size_t i = 0; i < ra.size(); ++i) CHECK(ra[i] == Approx(rb[i]).margin(1e-6));
}

#ifdef KANEGEN_HAVE_AOT_SIM
TEST_CASE("AOT simulator built by kanegen_add_model reproduces the generic engine", "[aot][generated]") {
  const fs::path tmp = fs::temp_directory_path() / ("kanegen_aot_" + std::to_string(getpid()));
  fs::create_directories(tmp);
  const std::string aot = (tmp / "aot.csv").string(), gen = (tmp / "generic.csv").string();
  const std::string model = test::source_path("models/double_pendulum.yaml");
  const std::string args = " --t-end 2 --dt-out 0.5 --integrator cvode-bdf --rtol 1e-11 --atol 1e-12";
  REQUIRE(std::system((std::string(kanegen::test::aot_simulator()) + args + " -o " + aot + " 2>/dev/null").c_str()) == 0);
  REQUIRE(std::system((std::string(kanegen::test::kanegen_binary()) + " simulate " + model + " --engine generic --no-progress" + args +
                       " -o " + gen + " 2>/dev/null")
                          .c_str()) == 0);
  auto rows = [](const std::string& path) {
    std::ifstream in(path);
    std::vector<std::string> lines;
    for (std::string l; std::getline(in, l);) lines.push_back(l);
    return lines;
  };
  const auto A = rows(aot), G = rows(gen);
  REQUIRE(A.size() == G.size());
  CHECK(A[0] == G[0]);  // same columns
  std::stringstream sa(A.back()), sg(G.back());
  for (std::string x, y; std::getline(sa, x, ',') && std::getline(sg, y, ',');)
    CHECK(std::stod(x) == Approx(std::stod(y)).margin(1e-7));
  // its -o is checked against its inputs before the run, as kanegen simulate's: a copy of the model (the same
  // text, so the hash check passes) given as --model and as -o is refused and left as it was
  const fs::path copy = tmp / "double_pendulum.yaml";
  fs::copy_file(model, copy);
  std::ifstream in(copy);
  const std::string text(std::istreambuf_iterator<char>(in), {});
  const std::string err = (tmp / "err.txt").string();
  const int status = std::system((std::string(kanegen::test::aot_simulator()) + args + " --model " + copy.string() +
                                  " -o " + copy.string() + " 2>" + err)
                                     .c_str());
  CHECK(WEXITSTATUS(status) == 2);
  std::ifstream e(err), again(copy);
  const std::string message(std::istreambuf_iterator<char>(e), {});
  INFO(message);
  CHECK(message.find("-o: cannot write") != std::string::npos);
  CHECK(message.find("it is an input of this command") != std::string::npos);
  CHECK(std::string(std::istreambuf_iterator<char>(again), {}) == text);
  fs::remove_all(tmp);
}
#endif

TEST_CASE("simulate: generated engine reproduces the generic run of explorer1_rigid", "[generated][simulate]") {
  const Model model = load_model(test::source_path("models/explorer1_rigid.yaml"));
  auto generated = test::generated_engine(model);
  GenericEngine generic(model);
  SimulationOptions opt;
  opt.t_end = 20.0;
  opt.dt_out = 5.0;
  opt.integrator.kind = IntegratorKind::arkode_erk;
  opt.integrator.rtol = 1e-11;
  opt.integrator.atol = 1e-13;
  std::ostringstream a, b;
  simulate(*generated, initial_state(model), opt, a);
  simulate(generic, initial_state(model), opt, b);
  std::istringstream ia(a.str()), ib(b.str());
  std::string la, lb;
  int rows = 0;
  while (std::getline(ia, la) && std::getline(ib, lb)) {
    if (rows++ == 0) {
      CHECK(la == lb);  // same columns
      continue;
    }
    std::stringstream sa(la), sb(lb);
    for (std::string x, y; std::getline(sa, x, ',') && std::getline(sb, y, ',');)
      CHECK(std::stod(x) == Approx(std::stod(y)).margin(1e-8 * std::max(1.0, std::abs(std::stod(y)))));
  }
  CHECK(rows == 6);
}
