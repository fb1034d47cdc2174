#include "tests/support/test_support.hpp"

#include <algorithm>
#include <cmath>

#include "engine/generic_engine.hpp"
#include "sim/simulate.hpp"
#include "model/state_io.hpp"

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <fstream>
#include <unistd.h>

namespace kanegen::test {

std::string write_temp(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / ("kanegen_tests_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

Drift run_invariants(const Model& model, double t_end, IntegratorKind kind, double rtol, int samples) {
  GenericEngine engine(model);
  const State s0 = initial_state(model);
  OdeProblem ode = make_ode_problem(engine, s0.tau, nullptr);
  IntegratorOptions opt;
  opt.kind = kind;
  opt.rtol = rtol;
  opt.atol = rtol * 1e-2;
  VecX x0(model.nq + model.nu);
  x0 << s0.q, s0.u;
  double E0 = 0, scaleE = 0;
  Vec3 p0, H0;
  Drift d;
  bool first = true;
  integrate(ode, opt, 0.0, x0, t_end, t_end / samples, [&](double, const VecX& x) {
    const VecX q = x.head(model.nq), u = x.tail(model.nu);
    const EnergyValues E = engine.energy(q, u);
    const MomentumValues P = engine.momentum(q, u);
    if (first) {
      E0 = E.T + E.V;
      p0 = P.p_N;
      H0 = P.H_N;
      first = false;
    }
    scaleE = std::max(scaleE, std::abs(E.T) + std::abs(E.V));
    d.energy = std::max(d.energy, std::abs(E.T + E.V - E0) / scaleE);
    d.p = std::max(d.p, (P.p_N - p0).norm() / std::max(1.0, p0.norm()));
    d.H = std::max(d.H, (P.H_N - H0).norm() / std::max(1.0, H0.norm()));
    return true;
  });
  return d;
}

const char* source_dir() { return KANEGEN_SOURCE_DIR; }
const char* build_dir() { return KANEGEN_BUILD_DIR; }
const char* kanegen_binary() { return KANEGEN_BINARY; }
const char* jit_cache_dir() { return KANEGEN_TEST_CACHE_DIR; }
const char* per_model_list() { return KANEGEN_PER_MODEL_LIST; }
#ifdef KANEGEN_AOT_SIM
const char* aot_simulator() { return KANEGEN_AOT_SIM; }
#else
const char* aot_simulator() { return ""; }
#endif

std::vector<std::string> all_models() {
  std::vector<std::string> files = model_files();
  for (const auto& d : std::filesystem::directory_iterator(source_path("tests/reference")))
    if (d.is_directory()) files.push_back((d.path() / (d.path().filename().string() + ".yaml")).string());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::string> models_under_test(const std::vector<std::string>& files) {
  const char* one = std::getenv("KANEGEN_TEST_MODEL");
  if (!one || !*one) return files;
  const std::string path = source_path(one);
  for (const auto& f : files)
    if (std::filesystem::path(f) == std::filesystem::path(path)) return {f};
  throw std::runtime_error(std::string("KANEGEN_TEST_MODEL=") + one + " names none of this test's models");
}

std::vector<std::string> model_files() {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::recursive_directory_iterator(source_path("models"))) {
    const std::string p = e.path().string();
    // models/spinup/ holds the benchmark's script-generated models (their own test: test_spinup.cpp)
    if (e.path().extension() == ".yaml" && p.find(".modal.") == std::string::npos && p.find("/spinup/") == std::string::npos)
      out.push_back(p);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace kanegen::test
