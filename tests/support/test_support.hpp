// Shared helpers and tolerances of the test suite.
#pragma once

#include <Eigen/Dense>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>
#include <unistd.h>

#include "codegen/jit_generator.hpp"
#include "engine/jit.hpp"
#include "model/diagnostics.hpp"
#include "model/model.hpp"
#include "sim/integrators.hpp"
#include "tests/support/tolerances.hpp"

namespace kanegen::test {

/// The paths of this build: compiled into test_support.cpp alone (the other
/// translation units are the same in every clone, so a second clone's build
/// takes them from ccache).
const char* source_dir();
const char* build_dir();
const char* kanegen_binary();   ///< the kanegen CLI
const char* jit_cache_dir();    ///< the suite's JIT cache
const char* per_model_list();   ///< the models CMake made per-model tests for
const char* aot_simulator();    ///< double_pendulum_sim ("" when not built)

inline std::string source_path(const std::string& rel) { return std::string(kanegen::test::source_dir()) + "/" + rel; }

/// max |a - b| / max(max|b|, floor): the error relative to the largest entry.
inline double rel_err(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double floor = 1e-300) {
  const double scale = std::max(b.cwiseAbs().maxCoeff(), floor);
  return (a - b).cwiseAbs().maxCoeff() / scale;
}

/// JIT options of the test suite: a cache inside the build tree, shared by
/// the test runs (KANEGEN_TEST_CACHE_DIR), and the quickest build (-O0, the
/// baseline ISA, every function): the suite checks what the code computes,
/// not how fast, and ctest's fixture "jit: <model>" builds each model's code
/// once for every test that asks for it (tests/CMakeLists.txt).
inline JitOptions jit_options() {
  JitOptions o;
  o.cache_dir = kanegen::test::jit_cache_dir();
  o.quiet = true;  // the suite's output stays readable
  o.quick = true;
  return o;
}

/// The model's generated engine, through the JIT with the suite's cache
/// (`form`: the generator's u-dot form, "auto", "composite" or "articulated").
inline std::unique_ptr<GeneratedEngine> generated_engine(const Model& model, const std::string& form = "auto") {
  codegen::GeneratorOptions g;
  g.udot_form = form;
  return jit_load(model, codegen::jit_code_generator(g), jit_options());
}

/// The model's code in both u-dot forms, each compiled once: the generator's own choice ("auto", which
/// the crosscheck and most tests load) and the other form by name. (Loading the chosen form by name
/// too would compile the same code a second time.) The form is the one the cache's record names.
inline std::vector<std::unique_ptr<GeneratedEngine>> generated_engines_in_both_forms(const Model& model) {
  std::vector<std::unique_ptr<GeneratedEngine>> e;
  e.push_back(generated_engine(model, "auto"));
  const std::string chosen = e[0]->udot_form();
  if (chosen != "composite" && chosen != "articulated")
    throw std::runtime_error("the JIT cache's record of " + model.name + " names no u-dot form");
  e.push_back(generated_engine(model, chosen == "composite" ? "articulated" : "composite"));
  return e;
}

/// Largest relative drifts along a run: E = T + V relative to max |T| + |V|;
/// p and H relative to their initial norms (floored at 1).
struct Drift {
  double energy = 0, p = 0, H = 0;
};

/// Integrates the model (generic engine) from its initial state to t_end with
/// `kind` at rtol (atol = rtol/100), sampling the invariants `samples` times.
Drift run_invariants(const Model& model, double t_end, IntegratorKind kind, double rtol, int samples = 50);

/// Every model file under models/ (modal files and the generated benchmark
/// models of models/spinup/ excluded), sorted.
std::vector<std::string> model_files();

/// Every model the every-model tests run on: model_files() and the reference
/// models (tests/reference/<name>/<name>.yaml), sorted.
std::vector<std::string> all_models();

/// The models an every-model test runs on now: `files`, or, under ctest's
/// per-model entries (tests/CMakeLists.txt), the one $KANEGEN_TEST_MODEL names
/// (a path relative to the source tree; one that names none of `files` fails).
std::vector<std::string> models_under_test(const std::vector<std::string>& files);

/// Writes `text` to a fresh temporary file with the given name and returns its path.
std::string write_temp(const std::string& name, const std::string& text);

/// A file's whole text.
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// tests/data/<rel>.
inline std::string data_path(const std::string& rel) { return source_path("tests/data/" + rel); }

/// A file of the shared NASTRAN run (tests/data/fea/pynastran_beam_modes/).
inline std::string shared_run(const std::string& file) {
  return source_path("tests/data/fea/pynastran_beam_modes/" + file);
}

/// An empty scratch directory of this process: <tmp>/kanegen-<tag>-<pid>-<name>.
inline std::filesystem::path scratch_dir(const std::string& tag, const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() /
                 ("kanegen-" + tag + "-" + std::to_string(getpid()) + "-" + name);
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

/// Diagnostics one per line (a test's INFO).
inline std::string dump(const std::vector<Diagnostic>& ds) {
  std::string s;
  for (const auto& d : ds) s += d.str() + "\n";
  return s;
}

/// Earth's gravitational parameter, m^3/s^2 (the tests' orbits).
constexpr double kMu = 3.986004418e14;

}  // namespace kanegen::test
