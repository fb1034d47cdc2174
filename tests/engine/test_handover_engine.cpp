// HandoverEngine: the generic engine until the background build is ready, the
// generated code from then on; a failed build leaves the run on the generic
// engine. Runs are compared against each engine alone.
#include <catch2/catch.hpp>

#include <chrono>
#include <sstream>
#include <thread>

#include "engine/generic_engine.hpp"
#include "engine/handover_engine.hpp"
#include "engine/load_model.hpp"
#include "sim/simulate.hpp"
#include "model/state_io.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

SimulationOptions options(double t_end) {
  SimulationOptions opt;
  opt.t_end = t_end;
  opt.dt_out = t_end / 4;
  opt.integrator.kind = IntegratorKind::rkf78;
  opt.integrator.rtol = 1e-11;
  opt.integrator.atol = 1e-13;
  return opt;
}

/// The CSV's last row as numbers.
std::vector<double> last_row(const std::string& csv) {
  std::istringstream in(csv);
  std::string line, last;
  while (std::getline(in, line)) last = line;
  std::vector<double> v;
  std::stringstream s(last);
  for (std::string x; std::getline(s, x, ',');) v.push_back(std::stod(x));
  return v;
}

double max_rel_diff(const std::vector<double>& a, const std::vector<double>& b) {
  REQUIRE(a.size() == b.size());
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]) / std::max(1.0, std::abs(b[i])));
  return d;
}

std::string run(Engine& e, const Model& m, double t_end) {
  std::ostringstream csv;
  simulate(e, initial_state(m), options(t_end), csv);
  return csv.str();
}

}  // namespace

TEST_CASE("handover engine: a failed build keeps the generic engine, bit for bit", "[handover]") {
  const Model model = load_model(test::source_path("models/double_pendulum.yaml"));
  HandoverEngine h(
      model, [] { throw std::runtime_error("no compiler here"); },
      [&model] { return std::unique_ptr<Engine>(test::generated_engine(model)); });
  h.wait();
  CHECK(h.error() == "no compiler here");
  GenericEngine generic(model);
  CHECK(run(h, model, 2.0) == run(generic, model, 2.0));
  CHECK_FALSE(h.handed_over());
  CHECK(h.name() == "generic");
}

TEST_CASE("handover engine: a build ready at the start runs the generated code, bit for bit", "[handover][generated]") {
  const Model model = load_model(test::source_path("models/double_pendulum.yaml"));
  auto generated = test::generated_engine(model);
  HandoverEngine h(
      model, [] {}, [&model] { return std::unique_ptr<Engine>(test::generated_engine(model)); });
  h.wait();
  REQUIRE(h.error().empty());
  // energy and momentum come from the generic engine: compare the state columns
  const std::vector<double> a = last_row(run(h, model, 2.0)), b = last_row(run(*generated, model, 2.0));
  CHECK(h.handed_over());
  CHECK(h.handover_time() == 0.0);
  const std::size_t n_state = 1 + model.nq + model.nu;  // t, q, u
  CHECK(std::vector<double>(a.begin(), a.begin() + n_state) == std::vector<double>(b.begin(), b.begin() + n_state));
}

TEST_CASE("handover engine: a build ready during the run takes over, the run agrees with both engines alone",
          "[handover][generated]") {
  const Model model = load_model(test::source_path("models/explorer1_rigid.yaml"));
  auto generated = test::generated_engine(model);  // cached before the clock matters
  GenericEngine generic(model);
  // the build becomes ready 20 ms into the run; the generic engine alone takes longer for this horizon
  HandoverEngine h(
      model, [] { std::this_thread::sleep_for(std::chrono::milliseconds(20)); },
      [&model] { return std::unique_ptr<Engine>(test::generated_engine(model)); });
  const double t_end = 200.0;
  std::ostringstream csv;
  const SimulationResult r = simulate(h, initial_state(model), options(t_end), csv);
  const std::vector<double> a = last_row(csv.str());
  REQUIRE(h.handed_over());
  CHECK(h.handover_time() > 0.0);
  CHECK(h.handover_time() < t_end);
  CHECK(h.name().find("then generated") != std::string::npos);
  // the same equations on both sides of the handover: the final state agrees
  // with each engine's own run to the tolerance's scale, and the torque-free
  // spacecraft's |H| holds across it (its damped hinges dissipate energy)
  CHECK(max_rel_diff(a, last_row(run(generic, model, t_end))) < 1e-7);
  CHECK(max_rel_diff(a, last_row(run(*generated, model, t_end))) < 1e-7);
  CHECK(r.quality.H_drift < 1e-9);
}

TEST_CASE("handover engine: a failed load keeps the generic engine and says why", "[handover]") {
  const Model model = load_model(test::source_path("models/double_pendulum.yaml"));
  HandoverEngine h(
      model, [] {}, []() -> std::unique_ptr<Engine> { throw std::runtime_error("no library in the cache"); });
  REQUIRE(h.wait(60.0));
  GenericEngine generic(model);
  CHECK(run(h, model, 1.0) == run(generic, model, 1.0));
  CHECK_FALSE(h.handed_over());
  CHECK(h.error() == "no library in the cache");
}
