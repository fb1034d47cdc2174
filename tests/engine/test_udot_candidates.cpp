// The JIT's u-dot candidates (engine/udot_candidates.hpp): a long u-dot is
// also built by a second compiler (clang++), a long straight-line one as
// compact code by both compilers, a compact one of 2,000-6,000 operations as
// straight-line code by both, all raced in one race against the library's own
// at the initial state (engine/udot_race.hpp) and served only when measured faster. Every build
// must compute the same u-dot as the generic engine, whichever is served; the
// choice is recorded and reused from the cache.
#include <catch2/catch.hpp>
#include <dlfcn.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <random>

#include "codegen/jit_generator.hpp"
#include "engine/generic_engine.hpp"
#include "engine/jit.hpp"
#include "engine/jit_cache.hpp"
#include "engine/load_model.hpp"
#include "engine/udot_candidates.hpp"
#include "engine/udot_race.hpp"
#include "model/state_io.hpp"
#include "tests/support/random_chain.hpp"
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

/// Random states for check_against_generic: `count` draws of u and tau (and q unless the attitude is kept:
/// a free base's quaternion stays the initial one) uniform in [-amplitude, amplitude].
struct RandomStates {
  unsigned seed = 1;
  int count = 3;
  double amplitude = 1.0;
  bool random_q = true;
};

/// u-dot by `fn` (called through e) against the generic engine's at random states, relative error below tol.
void check_against_generic(const GeneratedEngine& e, const Model& model, KanegenFunctionPtr fn, const RandomStates& r,
                           double tol) {
  GenericEngine g(model);
  State s = initial_state(model);
  std::mt19937 rng(r.seed);
  std::uniform_real_distribution<double> d(-r.amplitude, r.amplitude);
  for (int k = 0; k < r.count; ++k) {
    if (r.random_q)
      for (int i = 0; i < model.nq; ++i) s.q(i) = d(rng);
    for (int i = 0; i < model.nu; ++i) s.u(i) = d(rng), s.tau(i) = d(rng);
    VecX expected, by_fn(model.nu);
    g.udot(s.q, s.u, s.tau, expected);
    REQUIRE(e.call_udot(fn, s.t, s.q, s.u, s.tau, by_fn.data()) == 0);
    CHECK(test::rel_err(by_fn, expected) < tol);
  }
}

}  // namespace

TEST_CASE("u-dot candidates are built, raced, the fastest served only when faster, and recorded",
          "[jit][udot-candidates]") {
  REQUIRE(std::system("command -v clang++ > /dev/null 2>&1") == 0);  // scripts/install_deps.sh installs clang
  const SecondCompilerEnv env("clang++");
  const SecondCompilerCache cache;
  // 3,777 operations of straight-line u-dot, a free base and flexible modes
  const Model model = load_model(test::source_path("models/gravity_gradient_boom.yaml"));
  auto e = jit_load(model, codegen::jit_code_generator(), cache.options());
  GenericEngine g(model);
  const KanegenFunctionPtr own = e->function("udot");
  const std::string main_form = codegen::generate(model).udot_form;
  int preferred = 0;
  std::string served;
  for (const auto& [tag, name] : {std::pair<std::string, std::string>{"second", "clang++"},
                                  {"compact", "compact"},
                                  {"compact-second", "compact by clang++"}}) {
    INFO(tag);
    const std::string path = udot_candidate_path(e->library_path(), tag);
    const auto record = jit_cache::verified_record(path);
    REQUIRE(record);
    CHECK(record->compiler == name);
    // compact code in the form the main code has (the generator's choice: fewer operations)
    CHECK(record->udot_form == main_form);
    CHECK(record->udot_ns > 0);
    CHECK(record->main_udot_ns > 0);
    // served only when measured 5 % faster (second_wins), and then the fastest of them
    if (record->preferred) {
      CHECK(record->udot_ns < 0.95 * record->main_udot_ns);
      ++preferred;
      served = name;
    }
    // the candidate against the generic engine, at the initial attitude with random speeds and inputs
    std::shared_ptr<void> handle;
    const KanegenFunctionPtr fn = udot_of_library(path, record->api_symbol, handle);
    REQUIRE(fn != own);
    const RandomStates states{11, 4, 0.5, false};
    check_against_generic(*e, model, own, states, 1e-12);
    check_against_generic(*e, model, fn, states, 1e-12);
    // and the engine's u-dot, whichever it serves
    State s = initial_state(model);
    s.u.setConstant(0.3);
    VecX expected, by_engine;
    g.udot(s.q, s.u, s.tau, expected);
    e->udot(s.q, s.u, s.tau, by_engine);
    CHECK(test::rel_err(by_engine, expected) < 1e-12);
  }
  CHECK(preferred <= 1);
  CHECK(e->udot_compiler() == served);

  // From the cache: the recorded choice, no second race (the records are unchanged).
  const auto before = jit_cache::verified_record(udot_candidate_path(e->library_path(), "compact"));
  auto e2 = jit_load(model, codegen::jit_code_generator(), cache.options());
  CHECK(e2->udot_compiler() == e->udot_compiler());
  const auto after = jit_cache::verified_record(udot_candidate_path(e->library_path(), "compact"));
  REQUIRE(after);
  CHECK(after->udot_ns == before->udot_ns);
}

TEST_CASE("no u-dot candidates for short u-dot, no second compiler when told none", "[jit][udot-candidates]") {
  const SecondCompilerCache cache;
  {
    const SecondCompilerEnv env("clang++");
    // 175 operations: under 500 both compilers' code is as fast (chain_2)
    const Model small = load_model(test::source_path("models/double_pendulum.yaml"));
    auto e = jit_load(small, codegen::jit_code_generator(), cache.options());
    CHECK_FALSE(fs::exists(udot_candidate_path(e->library_path(), "second")));
    CHECK_FALSE(fs::exists(udot_candidate_path(e->library_path(), "compact")));
    CHECK(e->udot_compiler().empty());
  }
  {
    const SecondCompilerEnv env("none");
    const Model model = load_model(test::source_path("models/gravity_gradient_boom.yaml"));
    auto e = jit_load(model, codegen::jit_code_generator(), cache.options());
    CHECK_FALSE(fs::exists(udot_candidate_path(e->library_path(), "second")));
    CHECK_FALSE(fs::exists(udot_candidate_path(e->library_path(), "compact-second")));
    CHECK(fs::exists(udot_candidate_path(e->library_path(), "compact")));
    CHECK(e->udot_compiler() != "clang++");
    CHECK(e->udot_compiler() != "compact by clang++");
  }
}

TEST_CASE("compact u-dot is raced against the second compiler's build of it", "[jit][udot-candidates]") {
  REQUIRE(std::system("command -v clang++ > /dev/null 2>&1") == 0);
  const SecondCompilerEnv env("clang++");
  const SecondCompilerCache cache;
  // a 12-link chain's u-dot as compact code (2,000 operations and more): its one candidate is clang++'s build
  const Model model = load_model(test::write_temp("candidates_chain12.yaml", test::random_chain(12, 5)));
  codegen::GeneratorOptions go;
  go.udot_code = "compact";
  REQUIRE_FALSE(codegen::generate(model, go).find("udot")->kernels.empty());
  auto e = jit_load(model, codegen::jit_code_generator(go), cache.options());
  CHECK_FALSE(fs::exists(udot_candidate_path(e->library_path(), "compact")));
  const std::string path = udot_candidate_path(e->library_path(), "second");
  const auto record = jit_cache::verified_record(path);
  REQUIRE(record);
  CHECK(record->compiler == "clang++");
  CHECK(record->udot_ns > 0);
  CHECK(e->udot_compiler() == (record->preferred ? "clang++" : ""));
  std::shared_ptr<void> handle;
  const KanegenFunctionPtr fn = udot_of_library(path, record->api_symbol, handle);
  check_against_generic(*e, model, fn, RandomStates{3}, 1e-11);
}

namespace {
KanegenFunctionPtr g_real_udot = nullptr;
/// the real u-dot done eight times over: the same output, eight times the work
int udot_eight_times(const KanegenArgs* a, double* out) {
  int status = 0;
  for (int k = 0; k < 8; ++k) status = g_real_udot(a, out);
  return status;
}
int g_nu = 0;
/// the real u-dot with its first entry off by 1e-3 of the largest
int udot_off(const KanegenArgs* a, double* out) {
  const int status = g_real_udot(a, out);
  double largest = 0;
  for (int i = 0; i < g_nu; ++i) largest = std::max(largest, std::abs(out[i]));
  out[0] += 1e-3 * largest;
  return status;
}
/// the real u-dot with its last entry 1e300 (a broken build)
int udot_huge(const KanegenArgs* a, double* out) {
  const int status = g_real_udot(a, out);
  out[g_nu - 1] = 1e300;
  return status;
}
}  // namespace

TEST_CASE("race_udots: every candidate against the reference in one race", "[jit][udot-candidates]") {
  const SecondCompilerCache cache;
  const SecondCompilerEnv env("none");
  const Model model = load_model(test::source_path("models/double_pendulum.yaml"));
  auto e = jit_load(model, codegen::jit_code_generator(), cache.options());
  g_real_udot = e->udot_function();
  g_nu = model.nu;
  State s = initial_state(model);
  s.u(0) = 0.7, s.u(1) = -0.4;
  const std::vector<UdotRace> races = race_udots(*e, {g_real_udot, g_real_udot, udot_eight_times, udot_off}, s);
  REQUIRE(races.size() == 3);
  for (const UdotRace& r : races) {
    CHECK(r.first_status == 0);
    CHECK(r.second_status == 0);
    CHECK(r.first_ns == races.front().first_ns);  // one reference time for all
    CHECK(r.first_ns > 0);
  }
  CHECK(races[0].max_rel_diff == 0);  // itself
  CHECK(races[1].max_rel_diff == 0);  // the same output, eight times the work: ranked slower
  CHECK(races[1].second_ns > 2 * races[1].first_ns);
  CHECK_FALSE(second_wins(races[1]));
  CHECK(races[2].max_rel_diff == Approx(1e-3).epsilon(1e-6));  // another output: never served
  CHECK_FALSE(second_wins(races[2]));
  // agreement is measured against the reference's outputs: a broken candidate's huge ones hide nothing
  const std::vector<UdotRace> with_huge = race_udots(*e, {g_real_udot, udot_huge, udot_off}, s, 3);
  REQUIRE(with_huge.size() == 2);
  CHECK(with_huge[0].max_rel_diff > 1e100);
  CHECK_FALSE(second_wins(with_huge[0]));
  CHECK(with_huge[1].max_rel_diff == races[2].max_rel_diff);
  CHECK_FALSE(second_wins(with_huge[1]));
  // the pairwise race is the two-function case of the same
  const UdotRace pair = race_udot(*e, g_real_udot, udot_off, s);
  CHECK(pair.max_rel_diff == races[2].max_rel_diff);
  CHECK(race_udots(*e, {g_real_udot}, s).empty());
}

TEST_CASE("compact u-dot near the threshold is raced against straight-line code by both compilers",
          "[jit][udot-candidates]") {
  REQUIRE(std::system("command -v clang++ > /dev/null 2>&1") == 0);
  const SecondCompilerEnv env("clang++");
  const SecondCompilerCache cache;
  // an 8-link chain: compact code by the cost model (2,000 to 6,000 operations, kernels shared)
  const Model model = load_model(test::write_temp("candidates_chain8.yaml", test::random_chain(8, 7)));
  const codegen::EmittedFunction& main_udot = *codegen::generate(model).find("udot");
  REQUIRE_FALSE(main_udot.kernels.empty());
  REQUIRE(main_udot.ops.total() <= 6000);
  auto e = jit_load(model, codegen::jit_code_generator(), cache.options());
  CHECK_FALSE(fs::exists(udot_candidate_path(e->library_path(), "compact")));
  int preferred = 0;
  std::string served;
  for (const auto& [tag, name] : {std::pair<std::string, std::string>{"second", "clang++"},
                                  {"straight", "straight-line"},
                                  {"straight-second", "straight-line by clang++"}}) {
    INFO(tag);
    const std::string path = udot_candidate_path(e->library_path(), tag);
    const auto record = jit_cache::verified_record(path);
    REQUIRE(record);
    CHECK(record->compiler == name);
    CHECK(record->udot_form == e->udot_form());
    if (record->preferred) ++preferred, served = name;
    std::shared_ptr<void> handle;
    const KanegenFunctionPtr fn = udot_of_library(path, record->api_symbol, handle);
    check_against_generic(*e, model, fn, RandomStates{5}, 1e-11);
  }
  CHECK(preferred <= 1);
  CHECK(e->udot_compiler() == served);
  // a second load serves what the race chose, from the records
  auto again = jit_load(model, codegen::jit_code_generator(), cache.options());
  CHECK(again->udot_compiler() == served);
  // publishing a library removes every candidate of the one it replaces, of every tag (records first)
  const std::vector<std::string> all_tags{"second", "second-v3", "compact", "compact-second", "compact-second-v3",
                                          "straight", "straight-second", "straight-second-v3"};
  for (const std::string& tag : all_tags) {
    const std::string path = udot_candidate_path(e->library_path(), tag);
    if (!fs::exists(path)) std::ofstream(path) << "x", std::ofstream(jit_cache::record_path(path)) << "{}";
  }
  remove_udot_candidates(e->library_path());
  for (const std::string& tag : all_tags) {
    INFO(tag);
    CHECK_FALSE(fs::exists(udot_candidate_path(e->library_path(), tag)));
    CHECK_FALSE(fs::exists(jit_cache::record_path(udot_candidate_path(e->library_path(), tag))));
  }
}

TEST_CASE("second_wins: agreeing outputs and a clear margin", "[jit][udot-candidates]") {
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

TEST_CASE("the candidates planned: which code, which compiler, which entry file", "[jit][udot-candidates]") {
  Manifest m;
  m.udot_form = "composite";
  m.udot_code = "straight-line";
  m.functions.push_back({"udot", 3000});
  JitOptions o;
  o.compiler = "g++";
  o.flags = default_jit_flags();
  o.dispatch = false;  // the second compiler then builds for the baseline ISA: tags without -v3
  o.include_dir = "/include";
  const fs::path tmp = "/tmp/plan", entry = "/src/entry.cpp", compact = "/src/compact/entry.cpp";
  auto tags = [](const std::vector<UdotCandidate>& cs) {
    std::vector<std::string> t;
    for (const UdotCandidate& c : cs) t.push_back(c.tag);
    return t;
  };
  auto builds = [](const UdotCandidate& c, const fs::path& from) {
    return std::find(c.argv.begin(), c.argv.end(), from.string()) != c.argv.end();
  };
  {
    const SecondCompilerEnv env("clang++");
    // long straight-line u-dot: clang++'s build of it, and compact code by both compilers
    CHECK(other_udot_code(m, o) == "compact");
    const auto cs = plan_udot_candidates(m, o, tmp, entry, compact, "composite");
    REQUIRE(tags(cs) == std::vector<std::string>{"second", "compact", "compact-second"});
    CHECK((cs[0].name == "clang++" && cs[0].argv.front() == "clang++" && builds(cs[0], entry) && !builds(cs[0], compact)));
    CHECK((cs[1].name == "compact" && cs[1].argv.front() == "g++" && builds(cs[1], compact) && !builds(cs[1], entry)));
    CHECK((cs[2].name == "compact by clang++" && cs[2].argv.front() == "clang++" && builds(cs[2], compact)));
    for (const UdotCandidate& c : cs) CHECK(c.udot_form == "composite");
    // compact main code of at most 6,000 operations: clang++'s build of it, and straight-line code by both
    Manifest mc = m;
    mc.udot_code = "compact";
    mc.udot_form = "articulated";
    CHECK(other_udot_code(mc, o) == "straight-line");
    const fs::path straight = "/src/other/entry.cpp";
    const auto cc = plan_udot_candidates(mc, o, tmp, entry, straight, "articulated");
    REQUIRE(tags(cc) == std::vector<std::string>{"second", "straight", "straight-second"});
    CHECK((builds(cc[0], entry) && !builds(cc[0], straight)));
    CHECK((cc[1].name == "straight-line" && cc[1].argv.front() == "g++" && builds(cc[1], straight)));
    CHECK((cc[2].name == "straight-line by clang++" && cc[2].argv.front() == "clang++" && builds(cc[2], straight)));
    for (const UdotCandidate& c : cc) CHECK(c.udot_form == "articulated");
    // longer compact code: clang++'s build of that code only (compact code wins there at every ISA)
    Manifest ml = mc;
    ml.functions = {{"udot", 9000}};
    CHECK(other_udot_code(ml, o).empty());
    const auto cl = plan_udot_candidates(ml, o, tmp, entry, straight, "articulated");
    REQUIRE(tags(cl) == std::vector<std::string>{"second"});
    CHECK(builds(cl[0], entry));
    // shorter straight-line u-dot (500 to 2,000 operations): clang++'s build of it only
    Manifest mm = m;
    mm.functions = {{"udot", 1500}};
    CHECK(other_udot_code(mm, o).empty());
    const auto cm = plan_udot_candidates(mm, o, tmp, entry, compact, "composite");
    REQUIRE(tags(cm) == std::vector<std::string>{"second"});
    CHECK((cm[0].name == "clang++" && builds(cm[0], entry)));
    // short u-dot, or a quick build: none
    Manifest ms = m;
    ms.functions = {{"udot", 499}};
    CHECK(other_udot_code(ms, o).empty());
    CHECK(plan_udot_candidates(ms, o, tmp, entry, compact, "composite").empty());
    JitOptions quick = o;
    quick.quick = true;
    CHECK(plan_udot_candidates(m, quick, tmp, entry, compact, "composite").empty());
  }
  {
    const SecondCompilerEnv env("none");
    const auto cs = plan_udot_candidates(m, o, tmp, entry, compact, "composite");
    CHECK(tags(cs) == std::vector<std::string>{"compact"});
  }
}
