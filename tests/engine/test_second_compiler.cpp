// The JIT's second compiler for u-dot (engine/jit.cpp, "A second compiler for
// u-dot"): where clang++ is installed, a long straight-line u-dot is built by
// it too, raced against the main compiler's at the initial state
// (engine/udot_race.hpp) and served only when measured faster. Both builds
// must compute the same u-dot as the generic engine, whichever is served; the
// choice is recorded and reused from the cache.
#include <catch2/catch.hpp>
#include <dlfcn.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <random>

#include "codegen/jit_generator.hpp"
#include "engine/generic_engine.hpp"
#include "engine/jit.hpp"
#include "engine/jit_cache.hpp"
#include "engine/load_model.hpp"
#include "engine/udot_race.hpp"
#include "model/state_io.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;
namespace fs = std::filesystem;

namespace {

/// $KANEGEN_SECOND_CXX set for one scope (the suite may set it otherwise).
struct SecondCompilerEnv {
  std::string old;
  bool had = false;
  explicit SecondCompilerEnv(const char* value) {
    if (const char* v = std::getenv("KANEGEN_SECOND_CXX")) had = true, old = v;
    ::setenv("KANEGEN_SECOND_CXX", value, 1);
  }
  ~SecondCompilerEnv() {
    if (had)
      ::setenv("KANEGEN_SECOND_CXX", old.c_str(), 1);
    else
      ::unsetenv("KANEGEN_SECOND_CXX");
  }
};

struct SecondCompilerCache {
  fs::path dir;
  SecondCompilerCache() {
    std::random_device rd;
    dir = fs::temp_directory_path() / fmt::format("kanegen-second-compiler-{}-{:08x}", getpid(), rd());
    fs::create_directories(dir);
  }
  ~SecondCompilerCache() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  /// g++'s u-dot at the baseline ISA, the four functions every engine needs (a quicker build)
  JitOptions options() const {
    JitOptions o;
    o.cache_dir = dir.string();
    o.compiler = "g++";  // the main compiler (with $CXX=clang++ there would be no second one)
    o.dispatch = false;
    o.derivatives = false;
    o.only_set = true;
    return o;
  }
};

std::string second_path_of(const std::string& so_path) {
  fs::path p(so_path);
  p.replace_extension(".udot2.so");
  return p.string();
}

/// The u-dot of the library at `path` (its table's "udot"), the library kept open by `handle`.
KanegenFunctionPtr udot_of_library(const std::string& path, const std::string& api_symbol,
                                   std::shared_ptr<void>& handle) {
  void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  REQUIRE(h);
  handle.reset(h, [](void* p) { dlclose(p); });
  auto api_fn = reinterpret_cast<KanegenGeneratedApiFn>(dlsym(h, api_symbol.c_str()));
  REQUIRE(api_fn);
  const KanegenGeneratedApi* api = api_fn();
  REQUIRE(api->n_functions == 1);  // u-dot alone
  REQUIRE(std::string(api->functions[0].name) == "udot");
  return api->functions[0].fn;
}

}  // namespace

TEST_CASE("a second compiler's u-dot is built, raced, served only when faster, and recorded", "[jit][second-compiler]") {
  REQUIRE(std::system("command -v clang++ > /dev/null 2>&1") == 0);  // scripts/install_deps.sh installs clang
  const SecondCompilerEnv env("clang++");
  const SecondCompilerCache cache;
  // 3,777 operations of straight-line u-dot, a free base and flexible modes
  const Model model = load_model(test::source_path("models/gravity_gradient_boom.yaml"));
  auto e = jit_load(model, codegen::jit_code_generator(), cache.options());
  const std::string second = second_path_of(e->library_path());
  const auto record = jit_cache::verified_record(second);
  REQUIRE(record);
  CHECK(record->compiler == "clang++");
  CHECK(record->udot_ns > 0);
  CHECK(record->main_udot_ns > 0);
  // served exactly when measured 5 % faster (second_wins)
  CHECK(record->preferred == (record->udot_ns < 0.95 * record->main_udot_ns));
  CHECK(e->udot_compiler() == (record->preferred ? "clang++" : ""));

  // Both builds against the generic engine, at the initial attitude with random speeds and inputs.
  std::shared_ptr<void> handle;
  const KanegenFunctionPtr clang_udot = udot_of_library(second, record->api_symbol, handle);
  const KanegenFunctionPtr main_udot = e->function("udot");
  REQUIRE(clang_udot != main_udot);
  GenericEngine g(model);
  State s = initial_state(model);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> d(-0.5, 0.5);
  for (int k = 0; k < 4; ++k) {
    for (int i = 0; i < model.nu; ++i) s.u(i) = d(rng), s.tau(i) = d(rng);
    VecX expected, by_main(model.nu), by_clang(model.nu), served;
    g.udot(s.q, s.u, s.tau, expected);
    REQUIRE(e->call_udot(main_udot, s.t, s.q, s.u, s.tau, by_main.data()) == 0);
    REQUIRE(e->call_udot(clang_udot, s.t, s.q, s.u, s.tau, by_clang.data()) == 0);
    e->udot(s.q, s.u, s.tau, served);
    CHECK(test::rel_err(by_main, expected) < 1e-12);
    CHECK(test::rel_err(by_clang, expected) < 1e-12);
    CHECK(test::rel_err(served, expected) < 1e-12);
  }

  // From the cache: the recorded choice, no second race (the record is unchanged).
  auto e2 = jit_load(model, codegen::jit_code_generator(), cache.options());
  CHECK(e2->udot_compiler() == e->udot_compiler());
  const auto again = jit_cache::verified_record(second);
  REQUIRE(again);
  CHECK(again->udot_ns == record->udot_ns);
}

TEST_CASE("no second compiler for short or compact u-dot, nor when told none", "[jit][second-compiler]") {
  const SecondCompilerCache cache;
  {
    const SecondCompilerEnv env("clang++");
    // 186 operations: fits the instruction cache, the main compiler's code is as fast
    const Model small = load_model(test::source_path("models/double_pendulum.yaml"));
    auto e = jit_load(small, codegen::jit_code_generator(), cache.options());
    CHECK_FALSE(fs::exists(second_path_of(e->library_path())));
    CHECK(e->udot_compiler().empty());
  }
  {
    const SecondCompilerEnv env("none");
    const Model model = load_model(test::source_path("models/gravity_gradient_boom.yaml"));
    auto e = jit_load(model, codegen::jit_code_generator(), cache.options());
    CHECK_FALSE(fs::exists(second_path_of(e->library_path())));
    CHECK(e->udot_compiler().empty());
  }
}

TEST_CASE("second_wins: agreeing outputs and a clear margin", "[jit][second-compiler]") {
  UdotRace r;
  r.first_ns = 1000;
  r.second_ns = 900;
  CHECK(second_wins(r));
  r.second_ns = 960;  // within the 5 % margin: noise, keep the first
  CHECK_FALSE(second_wins(r));
  r.second_ns = 900;
  r.max_rel_diff = 1e-6;  // outputs disagree: never
  CHECK_FALSE(second_wins(r));
  r.max_rel_diff = 0;
  r.second_status = 3;  // a pivot the first did not meet
  CHECK_FALSE(second_wins(r));
}
