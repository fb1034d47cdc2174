// Speed report: ns per u-dot evaluation of the generated and the generic
// engine, measured interleaved in one run (median of repeated batches), for
// every model in models/ and tests/reference/ and for programmatic pin chains
// of 2..64 bodies; for the chains also generation time, compile time (cold
// JIT cache), header size and the operation count of u-dot. Prints markdown.
//   ./build/bench/kanegen_speed_report [--quick] [--chains 2,4,8,16,32,64]
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <random>
#include <sstream>

#include "model/chain_model.hpp"
#include "codegen/assembler.hpp"
#include "codegen/jit_generator.hpp"
#include "engine/resources.hpp"
#include "bench_support.hpp"
#include "engine/generic_engine.hpp"
#include "engine/jit.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"

using namespace kanegen;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {


struct Row {
  std::string name;
  int bodies, nu;
  double generic_ns, generated_ns;
  long ops;
  std::string form;
  double gen_s = 0, compile_s = 0;
  std::size_t header_bytes = 0;
};

Row measure(const Model& model, const JitOptions& jit, int repeats, bool cold) {
  Row r{model.name, static_cast<int>(model.bodies.size()), model.nu, 0, 0, 0, "", 0, 0, 0};
  const auto t0 = Clock::now();
  const codegen::EmittedModel code = codegen::generate(model);
  const codegen::AssembledFiles files = codegen::assemble(code, template_dir(), "model.hpp");
  r.gen_s = std::chrono::duration<double>(Clock::now() - t0).count();
  r.ops = code.find("udot")->ops.total();
  r.form = code.udot_form;
  r.header_bytes = files.header.size();
  JitOptions o = jit;
  if (cold) {
    o.cache_dir = (fs::path(jit.cache_dir) / ("cold-" + model.name)).string();
    fs::remove_all(o.cache_dir);
  }
  const auto t1 = Clock::now();
  auto generated = jit_load(model, codegen::jit_code_generator(), o);
  r.compile_s = std::chrono::duration<double>(Clock::now() - t1).count() - (cold ? r.gen_s : 0.0);
  GenericEngine generic(model);
  const State s = bench::random_state(model, 1, 0.5);
  VecX ud(model.nu);
  // Interleave the two engines so that machine noise hits both alike.
  const auto ns = bench::interleaved_ns_per_call({[&] { generic.udot(s.q, s.u, s.tau, ud); },
                                                  [&] { generated->udot(s.q, s.u, s.tau, ud); }},
                                                 3 * repeats, 2e-3);
  r.generic_ns = ns[0];
  r.generated_ns = ns[1];
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::vector<int> chains{2, 4, 8, 16, 32, 64};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") quick = true;
    if (a == "--chains" && i + 1 < argc) {
      chains.clear();
      std::stringstream ss(argv[++i]);
      for (std::string t; std::getline(ss, t, ',');) chains.push_back(std::stoi(t));
    }
  }
  const int repeats = quick ? 3 : 9;
  JitOptions jit;
  jit.cache_dir = (fs::temp_directory_path() / "kanegen_speed_report").string();

  std::vector<fs::path> files;
  for (const char* dir : {"models", "tests/reference"})
    for (const auto& e : fs::recursive_directory_iterator(fs::path(KANEGEN_SOURCE_DIR) / dir))
      if (e.path().extension() == ".yaml" && e.path().string().find(".modal.") == std::string::npos)
        files.push_back(e.path());
  std::sort(files.begin(), files.end());

  fmt::print("## u-dot evaluation, generated vs generic (median ns, one run)\n\n");
  fmt::print("| model | bodies | nu | u-dot ops (form) | generic ns | generated ns | speed-up |\n");
  fmt::print("|---|---:|---:|---:|---:|---:|---:|\n");
  for (const auto& f : files) {
    Model model;
    try {
      model = load_model(f.string());
    } catch (const std::exception&) {
      continue;
    }
    const Row r = measure(model, jit, repeats, false);
    fmt::print("| {} | {} | {} | {} ({}) | {:.0f} | {:.0f} | {:.1f}x |\n", r.name, r.bodies, r.nu, r.ops, r.form,
               r.generic_ns, r.generated_ns, r.generic_ns / r.generated_ns);
    std::fflush(stdout);
  }
  fmt::print("\n## Pin chains (spatial, axes cycling z, y, x)\n\n");
  fmt::print("| bodies | u-dot ops (form) | generic ns | generated ns | speed-up | generate s | compile s | header KiB |\n");
  fmt::print("|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (int n : chains) {
    const Model model = make_chain_model(n);
    const Row r = measure(model, jit, repeats, true);
    fmt::print("| {} | {} ({}) | {:.0f} | {:.0f} | {:.1f}x | {:.2f} | {:.2f} | {:.0f} |\n", n, r.ops, r.form,
               r.generic_ns, r.generated_ns, r.generic_ns / r.generated_ns, r.gen_s, r.compile_s,
               r.header_bytes / 1024.0);
    std::fflush(stdout);
  }
  return 0;
}
