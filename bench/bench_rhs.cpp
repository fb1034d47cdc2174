// Right-hand-side cost of the generic engine: ns per u-dot evaluation
// (kinematics, M, F, Cholesky solve) and per full ODE right-hand side
// (q-dot too), for every model in models/ and tests/reference/, at a
// random state. Not a test: speed targets live here.
//   ./build/bench/kanegen_bench [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <filesystem>
#include <random>

#include "bench_support.hpp"
#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"

using namespace kanegen;
namespace fs = std::filesystem;

namespace {


void bench_udot(benchmark::State& st, std::shared_ptr<Model> model) {
  GenericEngine engine(*model);
  const State s = bench::random_state(*model, 1);
  VecX udot(model->nu);
  for (auto _ : st) {
    engine.udot(s.q, s.u, s.tau, udot);
    benchmark::DoNotOptimize(udot.data());
  }
  st.counters["bodies"] = static_cast<double>(model->bodies.size());
  st.counters["nu"] = model->nu;
}

void bench_rhs(benchmark::State& st, std::shared_ptr<Model> model) {
  GenericEngine engine(*model);
  const State s = bench::random_state(*model, 2);
  VecX udot(model->nu), qdot(model->nq);
  for (auto _ : st) {
    engine.qdot(s.q, s.u, qdot);
    engine.udot(s.q, s.u, s.tau, udot);
    benchmark::DoNotOptimize(udot.data());
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<fs::path> files;
  for (const char* dir : {"models", "tests/reference"}) {
    const fs::path root = fs::path(KANEGEN_SOURCE_DIR) / dir;
    if (!fs::exists(root)) continue;
    for (const auto& e : fs::recursive_directory_iterator(root))
      if (e.path().extension() == ".yaml" && e.path().string().find(".modal.") == std::string::npos)
        files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    std::shared_ptr<Model> model;
    try {
      model = std::make_shared<Model>(load_model(f.string()));
    } catch (const std::exception& e) {
      continue;  // extreme/bad examples are not benchmarked
    }
    benchmark::RegisterBenchmark(("generic_udot/" + model->name).c_str(), bench_udot, model);
    benchmark::RegisterBenchmark(("generic_rhs/" + model->name).c_str(), bench_rhs, model);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
}
