// JIT plumbing: model hash, GeneratedEngine, compile cache (keys, checksums,
// damaged libraries, stale temporaries), concurrency and compiler failures.
// Most cases use the hand-written stand-in sources of
// tests/data/generated/pendulum_handwritten.* (no generator needed); the
// last ones use the generator.
#include <catch2/catch.hpp>
#include <fmt/format.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include "engine/generic_engine.hpp"
#include "engine/jit.hpp"
#include "model/model_hash.hpp"
#include "engine/load_model.hpp"
#include "model/parameters.hpp"
#include "model/state_io.hpp"
#include "tests/support/test_support.hpp"

#include "codegen/jit_generator.hpp"
#include "engine/jit_cache.hpp"

using namespace kanegen;
namespace fs = std::filesystem;

namespace {

/// A fresh cache directory, removed at the end of the test.
struct TempCache {
  fs::path dir;
  TempCache() {
    std::random_device rd;
    dir = fs::temp_directory_path() / fmt::format("kanegen-jit-test-{}-{:08x}", getpid(), rd());
    fs::create_directories(dir);
  }
  ~TempCache() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  JitOptions options() const {
    JitOptions o;
    o.cache_dir = dir.string();
    // the hand-written sources of these tests take no parameters; the real
    // generator's implicit parameters are tested on their own below
    o.implicit_parameters = false;
    return o;
  }
};

// The model of pendulum_handwritten.hpp (see the comment there).
constexpr double kM = 2.0, kL = 0.75, kIyy = 0.1, kGravity = 9.81, kK = 0.5, kC = 0.2, kRest = 0.1;

Model make_handwritten_pendulum() {
  Model m;
  m.name = "pendulum_handwritten";
  m.g_N = Vec3(0, 0, -kGravity);
  Body b;
  b.name = "bob";
  b.parent = -1;
  b.joint.type = JointType::revolute;
  b.joint.axis_J = Vec3::UnitY();
  b.joint.stiffness[0] = kK;
  b.joint.damping[0] = kC;
  b.joint.rest[0] = kRest;
  b.rigid.mass = kM;
  b.rigid.com_B = Vec3(kL, 0, 0);
  b.rigid.I_c_B = Vec3(0, kIyy, 0).asDiagonal();
  m.bodies.push_back(b);
  m.outputs.energy = true;
  m.outputs.momentum = true;
  m.outputs.reactions = false;
  finalize_model(m);
  return m;
}

using test::slurp;

/// The hand-written sources (header, entry, manifest) with the model's and
/// the generator's hashes filled in.
GeneratedSources handwritten_sources(const Model& model, const std::string& generator_hash = "handwritten") {
  auto read = [&](const std::string& ext) {
    std::string text = slurp(test::source_path("tests/data/generated/pendulum_handwritten" + ext));
    for (const auto& [from, to] : {std::pair<std::string, std::string>{"@MODEL_HASH@", model_hash(model)},
                                   std::pair<std::string, std::string>{"@GENERATOR_HASH@", generator_hash}})
      for (std::size_t p = 0; (p = text.find(from, p)) != std::string::npos; p += to.size())
        text.replace(p, from.size(), to);
    return text;
  };
  return {read(".hpp"), read(".entry.cpp"), read(".manifest.json")};
}

/// A stand-in generator giving the hand-written sources, counting its calls.
CodeGenerator handwritten_generator(int& calls, const std::string& hash = "handwritten") {
  CodeGenerator g;
  g.hash = hash;
  g.generate = [&calls, hash](const Model& m) {
    ++calls;
    return handwritten_sources(m, hash);
  };
  return g;
}

int count_entries(const fs::path& dir, const std::string& prefix) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind(prefix, 0) == 0) ++n;
  return n;
}

void check_pendulum_numbers(GeneratedEngine& e) {
  const Model& model = e.model();
  GenericEngine generic(model);
  const double th = 0.37, w = -1.3, tau = 0.25;
  VecX q(1), u(1), t(1);
  q << th;
  u << w;
  t << tau;
  const double M0 = kM * kL * kL + kIyy;
  const double F0 = kM * kGravity * kL * std::cos(th) - kK * (th - kRest) - kC * w + tau;

  MatX M, Mg;
  VecX F, Fg, ud, udg, qd;
  e.mass_matrix(q, M);
  e.forcing(q, u, t, F);
  e.udot(q, u, t, ud);
  e.qdot(q, u, qd);
  REQUIRE(M.rows() == 1);
  CHECK(M(0, 0) == Approx(M0).epsilon(1e-14));
  CHECK(F(0) == Approx(F0).epsilon(1e-14));
  CHECK(ud(0) == Approx(F0 / M0).epsilon(1e-14));
  CHECK(qd(0) == w);

  generic.mass_matrix(q, Mg);
  generic.forcing(q, u, t, Fg);
  generic.udot(q, u, t, udg);
  CHECK(test::rel_err(M, Mg) < test::kRoundoff);
  CHECK(test::rel_err(F, Fg) < test::kRoundoff);
  CHECK(test::rel_err(ud, udg) < test::kRoundoff);

  const EnergyValues E = e.energy(q, u), Eg = generic.energy(q, u);
  CHECK(E.T == Approx(0.5 * M0 * w * w).epsilon(1e-14));
  CHECK(E.T == Approx(Eg.T).epsilon(1e-12));
  CHECK(E.V == Approx(Eg.V).epsilon(1e-12));
  const MomentumValues P = e.momentum(q, u), Pg = generic.momentum(q, u);
  CHECK((P.p_N - Pg.p_N).norm() < 1e-12);
  CHECK((P.H_N - Pg.H_N).norm() < 1e-12);

  // Jacobian of [q'; u'] against central differences of [u; udot].
  MatX J;
  REQUIRE(e.jacobian(q, u, t, J));
  REQUIRE(J.rows() == 2);
  const double h = 1e-6;
  VecX up(1), um(1);
  VecX qp = q, qm = q;
  qp(0) += h;
  qm(0) -= h;
  e.udot(qp, u, t, up);
  e.udot(qm, u, t, um);
  CHECK(J(0, 0) == 0.0);
  CHECK(J(0, 1) == 1.0);
  CHECK(J(1, 0) == Approx((up(0) - um(0)) / (2 * h)).epsilon(1e-7));
  VecX u2p = u, u2m = u;
  u2p(0) += h;
  u2m(0) -= h;
  e.udot(q, u2p, t, up);
  e.udot(q, u2m, t, um);
  CHECK(J(1, 1) == Approx((up(0) - um(0)) / (2 * h)).epsilon(1e-7));

  // reactions were not requested: not in the table, a clear error here.
  CHECK(e.function("reactions") == nullptr);
  std::vector<Reaction> r;
  CHECK_THROWS_WITH(e.reactions(q, u, ud, r), Catch::Contains("without 'reactions' output"));
}

}  // namespace

TEST_CASE("model hash: stable for the same model, sensitive to every parameter", "[jit][model-hash]") {
  const std::string path = test::source_path("tests/reference/v_double3d/v_double3d.yaml");
  const Model a = load_model(path);
  const Model b = load_model(path);
  const std::string h = model_hash(a);
  CHECK(h.size() == 16);
  CHECK(h.find_first_not_of("0123456789abcdef") == std::string::npos);
  CHECK(model_hash(b) == h);
  CHECK(model_fingerprint(a) == model_fingerprint(b));
  CHECK(model_hash(a) == h);  // deterministic across calls

  auto differs = [&](auto&& change) {
    Model m = load_model(path);
    change(m);
    return model_hash(m) != h;
  };
  CHECK(differs([](Model& m) { m.bodies[0].rigid.mass = std::nextafter(m.bodies[0].rigid.mass, 10.0); }));
  CHECK(differs([](Model& m) { m.bodies[1].rigid.com_B.y() += 1e-15; }));
  CHECK(differs([](Model& m) { m.bodies[1].rigid.I_c_B(0, 1) += 1e-9; }));
  CHECK(differs([](Model& m) { m.bodies[0].joint.stiffness[0] += 1e-9; }));
  CHECK(differs([](Model& m) { m.bodies[0].joint.damping[0] += 1e-9; }));
  CHECK(differs([](Model& m) { m.bodies[0].joint.rest[0] += 1e-9; }));
  CHECK(differs([](Model& m) { m.bodies[1].joint.axis_J.x() += 1e-12; }));
  CHECK(differs([](Model& m) { m.bodies[1].joint.p_PJ.z() += 1e-12; }));
  CHECK(differs([](Model& m) { m.bodies[1].joint.R_PJ(2, 1) += 1e-12; }));
  CHECK(differs([](Model& m) { m.g_N.x() += 1e-12; }));
  CHECK(differs([](Model& m) { m.name += "x"; }));
  CHECK(differs([](Model& m) { m.bodies[1].name = "other"; }));
  CHECK(differs([](Model& m) { m.outputs.reactions = !m.outputs.reactions; }));
  CHECK(differs([](Model& m) { m.bodies[1].joint.type = JointType::prismatic; }));

  // What generated code does not depend on leaves the hash alone.
  CHECK_FALSE(differs([](Model& m) { m.description = "something else"; }));
  CHECK_FALSE(differs([](Model& m) { m.source_path = "/elsewhere/model.yaml"; }));
  CHECK_FALSE(differs([](Model& m) { m.q0(0) += 0.5; m.u0(1) -= 0.5; }));
  CHECK_FALSE(differs([](Model& m) { m.bodies[0].rigid.mass *= -0.0 * 0.0 + 1.0; }));

  // Flexible data: shapes and modal stiffness count.
  const std::string fpath = test::source_path("tests/data/good/flex_hub.yaml");
  const Model f = load_model(fpath);
  const std::string hf = model_hash(f);
  CHECK(model_hash(load_model(fpath)) == hf);
  for (std::size_t i = 0; i < f.bodies.size(); ++i) {
    if (!f.bodies[i].flex) continue;
    Model g = f;
    g.bodies[i].flex->Phi(0, 0) += 1e-13;
    CHECK(model_hash(g) != hf);
    g = f;
    g.bodies[i].flex->K(0) *= 1.0 + 1e-12;
    CHECK(model_hash(g) != hf);
    g = f;
    g.bodies[i].flex->nodes[0].mass += 1e-12;
    CHECK(model_hash(g) != hf);
  }
  // Second-order (foreshortening) data and prescribed motion count too.
  const Model sp = load_model(test::source_path("tests/reference/v_spinup/v_spinup.yaml"));
  const std::string hs = model_hash(sp);
  Model g = sp;
  g.bodies[1].flex->Gamma[2][0](0, 0) *= 1.0 + 1e-12;
  CHECK(model_hash(g) != hs);
  g = sp;
  g.bodies[1].flex->Gamma.assign(g.bodies[1].flex->nodes.size(), {});  // foreshortening off
  CHECK(model_hash(g) != hs);
  g = sp;
  g.bodies[0].joint.motion->rate += 1e-12;
  CHECK(model_hash(g) != hs);
  g = sp;
  g.bodies[0].joint.motion->kind = MotionKind::sine;
  CHECK(model_hash(g) != hs);
}

TEST_CASE("generated engine refuses a table that does not match the model", "[jit]") {
  const Model model = make_handwritten_pendulum();
  const std::string hash = model_hash(model);
  auto qd = +[](const KanegenArgs* a, double* o) {
    o[0] = a->u[0];
    return 0;
  };
  auto mm = +[](const KanegenArgs*, double* M) {
    M[0] = 1.0;
    return 0;
  };
  auto fo = +[](const KanegenArgs*, double* F) {
    F[0] = 0.0;
    return 0;
  };
  auto ud = +[](const KanegenArgs*, double*) { return 1; };
  const KanegenFunction fns[] = {{"qdot", qd, 1}, {"mass_matrix", mm, 1}, {"forcing", fo, 1}, {"udot", ud, 1}};
  KanegenGeneratedApi api{KANEGEN_GENERATED_API_VERSION, "pendulum_handwritten", hash.c_str(), "gen-a", 1, 1, 1, 0, 0, 0, 4, fns};
  {
    GeneratedEngine e(model, &api);
    VecX q = VecX::Zero(1), u = VecX::Zero(1), out;
    CHECK_THROWS_AS(e.udot(q, u, u, out), SingularMassMatrix);
    CHECK_THROWS_WITH(e.energy(q, u), Catch::Contains("without 'energy' output"));
    CHECK_THROWS_WITH(e.momentum(q, u), Catch::Contains("without 'momentum' output"));
    MatX J;
    CHECK_FALSE(e.jacobian(q, u, u, J));
    CHECK_FALSE(e.has_jacobian());
    CHECK_THROWS_AS(e.mass_matrix(VecX::Zero(2), J), std::invalid_argument);
  }
  KanegenGeneratedApi bad = api;
  bad.model_hash = "0123456789abcdef";
  CHECK_THROWS_WITH(GeneratedEngine(model, &bad), Catch::Contains("different version of the model"));
  bad = api;
  bad.api_version = KANEGEN_GENERATED_API_VERSION + 1;
  CHECK_THROWS_WITH(GeneratedEngine(model, &bad), Catch::Contains("API version"));
  bad = api;
  bad.nu = 2;
  CHECK_THROWS_WITH(GeneratedEngine(model, &bad), Catch::Contains("nu = 2"));
  // Code written by another generator than the one expected is refused.
  CHECK_THROWS_WITH(GeneratedEngine(model, &api, nullptr, "gen-b"), Catch::Contains("written by another generator"));
  bad = api;
  bad.n_functions = 3;  // no udot
  CHECK_THROWS_WITH(GeneratedEngine(model, &bad), Catch::Contains("lacks one of"));
  CHECK_THROWS(GeneratedEngine(model, nullptr));
}

TEST_CASE("compile_and_load: hand-written sources, cache hit, concurrent loads", "[jit]") {
  TempCache cache;
  const Model model = make_handwritten_pendulum();
  const GeneratedSources sources = handwritten_sources(model);
  const JitOptions opts = cache.options();
  const std::string so = (cache.dir / "pendulum_handwritten-test.so").string();

  // Two threads race on the same uncached library: both must succeed.
  std::unique_ptr<GeneratedEngine> e1, e2;
  std::string err1, err2;
  auto load = [&](std::unique_ptr<GeneratedEngine>& e, std::string& err) {
    try {
      e = compile_and_load(model, sources, so, opts);
    } catch (const std::exception& ex) {
      err = ex.what();
    }
  };
  std::thread th1(load, std::ref(e1), std::ref(err1));
  std::thread th2(load, std::ref(e2), std::ref(err2));
  th1.join();
  th2.join();
  INFO("thread errors: " << err1 << " | " << err2);
  REQUIRE(e1);
  REQUIRE(e2);
  REQUIRE(fs::exists(so));
  CHECK(count_entries(cache.dir, ".tmp-") == 0);  // nothing half-written left
  CHECK(e1->name() == "generated");
  CHECK(e1->library_path() == so);
  check_pendulum_numbers(*e1);
  check_pendulum_numbers(*e2);

  // Second load: a cache hit (no compile: the library untouched, no temporary made).
  struct stat st0 {};
  REQUIRE(stat(so.c_str(), &st0) == 0);
  e1.reset();
  e2.reset();
  GeneratedSources broken = sources;  // would fail to compile: proves no compile happens on a hit
  broken.entry = "#error not compiled on a cache hit\n";
  auto e3 = compile_and_load(model, broken, so, opts);
  struct stat st1 {};
  REQUIRE(stat(so.c_str(), &st1) == 0);
  CHECK(st1.st_mtim.tv_sec == st0.st_mtim.tv_sec);
  CHECK(st1.st_mtim.tv_nsec == st0.st_mtim.tv_nsec);
  CHECK(st1.st_ino == st0.st_ino);
  check_pendulum_numbers(*e3);

  // The same library against a model that differs: refused with a clear message.
  Model other = model;
  other.bodies[0].rigid.mass = 3.0;
  CHECK_THROWS_WITH(compile_and_load(other, sources, so, opts), Catch::Contains("different version of the model"));
}

TEST_CASE("compile_and_load from two processes at once", "[jit]") {
  TempCache cache;
  const Model model = make_handwritten_pendulum();
  const GeneratedSources sources = handwritten_sources(model);
  const JitOptions opts = cache.options();
  const std::string so = (cache.dir / "pendulum_handwritten-proc.so").string();
  std::fflush(nullptr);
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    int rc = 1;
    try {
      auto e = compile_and_load(model, sources, so, opts);
      VecX q = VecX::Constant(1, 0.2), m;
      MatX M;
      e->mass_matrix(q, M);
      rc = std::abs(M(0, 0) - (kM * kL * kL + kIyy)) < 1e-14 ? 0 : 3;
    } catch (...) {
      rc = 2;
    }
    _exit(rc);
  }
  std::unique_ptr<GeneratedEngine> e;
  std::string err;
  try {
    e = compile_and_load(model, sources, so, opts);
  } catch (const std::exception& ex) {
    err = ex.what();
  }
  int status = 0;
  REQUIRE(waitpid(child, &status, 0) == child);
  INFO(err);
  REQUIRE(e);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  CHECK(count_entries(cache.dir, ".tmp-") == 0);
  check_pendulum_numbers(*e);
}

TEST_CASE("a compile error throws JitError naming the compiler and the faulty line", "[jit]") {
  TempCache cache;
  const Model model = make_handwritten_pendulum();
  GeneratedSources sources = handwritten_sources(model);
  std::string& text = sources.header;
  const std::string needle = "qd[0] = u[0];";
  const auto pos = text.find(needle);
  REQUIRE(pos != std::string::npos);
  text.replace(pos, needle.size(), "qd[0] = u[0] +* ;  // kanegen-test-syntax-error");
  JitOptions opts = cache.options();
  opts.compiler = "c++";
  const std::string so = (cache.dir / "broken-test.so").string();
  try {
    compile_and_load(model, sources, so, opts);
    FAIL("no JitError");
  } catch (const JitError& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(what.find("c++ -std=c++20 -fPIC -O2 -DKANEGEN_PART_") != std::string::npos);  // the failing part's command
    CHECK(what.find("model 'pendulum_handwritten'") != std::string::npos);
    CHECK(what.find("model.hpp") != std::string::npos);
    CHECK(what.find("kanegen-test-syntax-error") != std::string::npos);  // the offending source line
    CHECK(what.find("sources kept in: ") != std::string::npos);
    CHECK(e.command.rfind("c++ ", 0) == 0);
    CHECK(fs::exists(fs::path(e.kept_dir) / "entry.cpp"));
    CHECK(fs::exists(fs::path(e.kept_dir) / "compiler.log"));
  }
  CHECK_FALSE(fs::exists(so));
  CHECK(count_entries(cache.dir, ".tmp-") == 0);
  for (const auto& f : fs::recursive_directory_iterator(cache.dir)) CHECK(f.path().extension() != ".so");

  // A compiler that cannot be run is a JitError too.
  opts.compiler = "kanegen-no-such-compiler-xyz";
  CHECK_THROWS_AS(compile_and_load(model, sources, so, opts), JitError);
}

TEST_CASE("jit_load: generate, compile, cache by model, flags and generator", "[jit]") {
  TempCache cache;
  const Model model = make_handwritten_pendulum();
  int generated = 0;
  const CodeGenerator fake = handwritten_generator(generated);
  const JitOptions opts = cache.options();
  const std::string path = jit_library_path(model, fake.hash, opts);
  CHECK(fs::path(path).parent_path() == cache.dir);
  CHECK(fs::path(path).filename().string().rfind("pendulum_handwritten-", 0) == 0);
  CHECK(fs::path(path).extension() == ".so");

  auto e = jit_load(model, fake, opts);
  CHECK(generated == 1);
  CHECK(e->library_path() == path);
  check_pendulum_numbers(*e);
  auto e2 = jit_load(model, fake, opts);
  CHECK(generated == 1);  // hit: no generation

  // Different flags, a different model or a different generator: a different library.
  JitOptions o2 = opts;
  o2.flags = "-O1 -std=c++20 -fPIC -shared";
  CHECK(jit_library_path(model, fake.hash, o2) != path);
  Model other = model;
  other.bodies[0].joint.damping[0] = 0.3;
  CHECK(jit_library_path(other, fake.hash, opts) != path);
  CHECK(jit_library_path(model, "another-generator", opts) != path);
  CHECK(jit_cache_key(model, fake.hash, opts) == jit_cache_key(make_handwritten_pendulum(), fake.hash, opts));

  // Defaults come from the environment.
  JitOptions none;
  ::setenv("KANEGEN_CACHE_DIR", cache.dir.c_str(), 1);
  CHECK(resolved(none).cache_dir == cache.dir.string());
  ::unsetenv("KANEGEN_CACHE_DIR");
  CHECK(resolved(none).flags == "-O2 -std=c++20 -fPIC -shared");
}

TEST_CASE("a changed generator never reuses a cached library", "[jit]") {
  TempCache cache;
  const Model model = make_handwritten_pendulum();
  int calls_a = 0, calls_b = 0;
  const CodeGenerator a = handwritten_generator(calls_a, "generator-a");
  const CodeGenerator b = handwritten_generator(calls_b, "generator-b");
  auto ea = jit_load(model, a, cache.options());
  auto eb = jit_load(model, b, cache.options());
  CHECK(calls_a == 1);
  CHECK(calls_b == 1);  // generated and compiled again, not taken from a's library
  CHECK(ea->library_path() != eb->library_path());
}

TEST_CASE("the generator hash follows the generator's sources and templates", "[jit][build]") {
  // cmake/GeneratorHash.cmake, as the build runs it: an edit of one source
  // file changes the hash (and so every JIT cache key).
  TempCache cache;
  const fs::path src = cache.dir / "a.cpp", tmpl = cache.dir / "t.in";
  std::ofstream(src) << "int f() { return 1; }\n";
  std::ofstream(tmpl) << "template\n";
  auto hash = [&] {
    const fs::path out = cache.dir / "hash.h";
    const std::string cmd = fmt::format("cmake -DINPUTS='{};{}' -DOUTPUT={} -P {} > /dev/null", src.string(),
                                        tmpl.string(), out.string(), test::source_path("cmake/GeneratorHash.cmake"));
    REQUIRE(std::system(cmd.c_str()) == 0);
    return slurp(out);
  };
  const std::string h1 = hash();
  CHECK(h1.find("#define KANEGEN_GENERATOR_HASH \"") != std::string::npos);
  CHECK(hash() == h1);  // deterministic
  std::ofstream(src) << "int f() { return 2; }\n";
  const std::string h2 = hash();
  CHECK(h2 != h1);
  std::ofstream(tmpl) << "template changed\n";
  CHECK(hash() != h2);
  // And the generator linked into this build reports a 16-hex-digit hash.
  const std::string g = codegen::generator_hash();
  CHECK(g.size() == 16);
  CHECK(g.find_first_not_of("0123456789abcdef") == std::string::npos);
}

TEST_CASE("a damaged cached library is detected and rebuilt, never loaded", "[jit]") {
  TempCache cache;
  const Model model = make_handwritten_pendulum();
  int calls = 0;
  const CodeGenerator gen = handwritten_generator(calls);
  const std::string so = jit_library_path(model, gen.hash, cache.options());
  jit_load(model, gen, cache.options());
  REQUIRE(calls == 1);
  REQUIRE(jit_cache::verified_record(so));
  const auto size = fs::file_size(so);

  SECTION("truncated") { fs::resize_file(so, size / 2); }
  SECTION("overwritten in the middle") {
    std::fstream f(so, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(size / 2));
    const std::string junk(256, '\xAB');
    f.write(junk.data(), static_cast<std::streamsize>(junk.size()));
  }
  SECTION("record missing") { fs::remove(jit_cache::record_path(so)); }
  CHECK_FALSE(jit_cache::verified_record(so));
  // Loading it would crash (SIGBUS/SIGSEGV) in dlopen or at a call; instead it is rebuilt.
  auto e = jit_load(model, gen, cache.options());
  CHECK(calls == 2);
  CHECK(jit_cache::verified_record(so));
  check_pendulum_numbers(*e);
}

TEST_CASE("temporary build directories of dead processes are removed", "[jit]") {
  TempCache cache;
  // A child makes a build directory and dies without cleaning it (as a killed compile does).
  std::fflush(nullptr);
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    jit_cache::make_temp_dir(cache.dir.string());
    _exit(0);
  }
  int status = 0;
  REQUIRE(waitpid(child, &status, 0) == child);
  REQUIRE(count_entries(cache.dir, ".tmp-") == 1);
  const std::string mine = jit_cache::make_temp_dir(cache.dir.string());  // a live process's
  jit_cache::remove_stale_temps(cache.dir.string());
  CHECK(count_entries(cache.dir, ".tmp-") == 1);
  CHECK(fs::exists(mine));
  // And a build cleans up before it starts.
  fs::remove_all(mine);
  const pid_t child2 = fork();
  if (child2 == 0) {
    jit_cache::make_temp_dir(cache.dir.string());
    _exit(0);
  }
  REQUIRE(waitpid(child2, &status, 0) == child2);
  int calls = 0;
  jit_load(make_handwritten_pendulum(), handwritten_generator(calls), cache.options());
  CHECK(count_entries(cache.dir, ".tmp-") == 0);
}

TEST_CASE("jit_load of v_double3d matches the generic engine", "[jit][generator]") {
  TempCache cache;
  const Model model = load_model(test::source_path("tests/reference/v_double3d/v_double3d.yaml"));
  auto e = jit_load(model, codegen::jit_code_generator(), cache.options());
  GenericEngine g(model);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> d(-2.0, 2.0);
  for (int s = 0; s < 5; ++s) {
    VecX q(model.nq), u(model.nu), tau(model.nu);
    for (int i = 0; i < model.nq; ++i) q(i) = d(rng);
    for (int i = 0; i < model.nu; ++i) u(i) = d(rng), tau(i) = d(rng);
    MatX M, Mg;
    VecX F, Fg, ud, udg;
    e->mass_matrix(q, M);
    g.mass_matrix(q, Mg);
    e->forcing(q, u, tau, F);
    g.forcing(q, u, tau, Fg);
    e->udot(q, u, tau, ud);
    g.udot(q, u, tau, udg);
    CHECK(test::rel_err(M, Mg) < test::kRoundoff);
    CHECK(test::rel_err(F, Fg) < test::kRoundoff);
    CHECK(test::rel_err(ud, udg) < test::kRoundoff);
  }
  // Second load: a cache hit (the same library, no new build directory).
  const std::string path = e->library_path();
  struct stat st0 {};
  REQUIRE(stat(path.c_str(), &st0) == 0);
  auto e2 = jit_load(model, codegen::jit_code_generator(), cache.options());
  struct stat st1 {};
  REQUIRE(stat(path.c_str(), &st1) == 0);
  CHECK(e2->library_path() == path);
  CHECK(st1.st_ino == st0.st_ino);
  CHECK(st1.st_mtim.tv_nsec == st0.st_mtim.tv_nsec);
}

TEST_CASE("a quick build without derivatives is cached apart, a full library, once cached, serves it", "[jit]") {
  const TempCache cache;
  const Model m = make_handwritten_pendulum();
  JitOptions lean = cache.options();
  lean.quiet = true;
  lean.derivatives = false;
  lean.quick = true;
  JitOptions full = cache.options();
  full.quiet = true;
  const auto gen = codegen::jit_code_generator();
  CHECK(jit_library_path(m, gen.hash, lean) != jit_library_path(m, gen.hash, full));
  const auto a = jit_load(m, gen, lean);
  CHECK(a->library_path() == jit_library_path(m, gen.hash, lean));
  CHECK(!a->has_jacobian());  // the dual-number functions were left out
  GenericEngine generic(m);
  VecX q(1), u(1), tau = VecX::Zero(1), ua, ug;
  q << 0.4;
  u << -0.3;
  a->udot(q, u, tau, ua);
  generic.udot(q, u, tau, ug);
  CHECK(std::abs(ua(0) - ug(0)) <= 1e-14 * std::abs(ug(0)));
  const auto b = jit_load(m, gen, full);
  CHECK(b->has_jacobian());
  const auto c = jit_load(m, gen, lean);  // now the optimized full library is used
  CHECK(c->library_path() == jit_library_path(m, gen.hash, full));
  CHECK(c->has_jacobian());
}

TEST_CASE("a compiler wrapped in a command that takes -o (e.g. /usr/bin/time -o log c++) builds", "[jit]") {
  const TempCache cache;
  // the wrapper: `wrap.sh -o LOG compiler args...` notes each call in LOG and runs the rest
  const fs::path wrapper = cache.dir / "wrap.sh", log = cache.dir / "calls.log";
  {
    std::ofstream f(wrapper);
    f << "#!/bin/sh\n[ \"$1\" = -o ] || exit 9\necho call >> \"$2\"\nshift 2\nexec \"$@\"\n";
  }
  fs::permissions(wrapper, fs::perms::owner_all);
  const Model m = make_handwritten_pendulum();
  for (const bool quick : {true, false}) {
    INFO((quick ? "quick" : "optimized") << " build");
    JitOptions o = cache.options();
    o.quiet = true;
    o.quick = quick;
    o.dispatch = false;
    o.compiler = fmt::format("{} -o {} c++", wrapper.string(), log.string());
    const auto e = jit_load(m, codegen::jit_code_generator(), o);
    GenericEngine generic(m);
    VecX q(1), u(1), tau = VecX::Zero(1), ue, ug;
    q << 0.4;
    u << -0.3;
    e->udot(q, u, tau, ue);
    generic.udot(q, u, tau, ug);
    CHECK(std::abs(ue(0) - ug(0)) <= 1e-14 * std::abs(ug(0)));
  }
  CHECK(fs::exists(log));
}

TEST_CASE("jit_load: editing a joint spring, damper or modal damping ratio reuses the cached library", "[jit]") {
  TempCache cache;
  JitOptions opts = cache.options();
  opts.implicit_parameters = true;
  opts.quiet = true;
  opts.derivatives = false;
  auto model_text = [](double k, double c, double zeta) {
    return fmt::format(
        "name: sprung\ngravity: [0, 0, -9.81]\nbodies:\n"
        "  - {{name: arm, parent: ground, joint: {{type: revolute, axis: [0, 1, 0], stiffness: {}, damping: {}, rest: 0.2}},\n"
        "     mass: 2.0, com: [0.5, 0, 0], inertia: [0.01, 0.2, 0.2, 0, 0, 0]}}\n"
        "  - name: beam\n    parent: arm\n    joint: {{type: fixed, position: [1.0, 0, 0]}}\n"
        "    flexible:\n      beam: {{length: 1.0, direction: x, mass_per_length: 0.5, EI: [20.0, 30.0], elements: 4, modes: 2}}\n"
        "      damping_ratio: {}\n"
        "initial:\n  q: {{arm.angle: 0.3, beam.eta1: 0.01}}\n  u: {{arm.angle_rate: 0.5, beam.eta2_rate: 0.1}}\n",
        k, c, zeta);
  };
  const Model m1 = load_model(test::write_temp("sprung1.yaml", model_text(2.0, 0.1, 0.01)));
  const Model m2 = load_model(test::write_temp("sprung2.yaml", model_text(5.0, 0.3, 0.05)));
  const Model m0 = load_model(test::write_temp("sprung0.yaml", model_text(0.0, 0.1, 0.01)));
  const CodeGenerator gen = codegen::jit_code_generator();
  CHECK(implicit_parameters(m1).size() == 5);  // stiffness, damping, rest, two damping ratios
  CHECK(jit_cache_key(m1, gen.hash, opts) == jit_cache_key(m2, gen.hash, opts));
  CHECK(jit_cache_key(m1, gen.hash, opts) != jit_cache_key(m0, gen.hash, opts));  // a zero stays folded
  auto e1 = jit_load(m1, gen, opts);
  CHECK(jit_cached(m2, gen, opts));
  auto e2 = jit_load(m2, gen, opts);
  CHECK(e1->library_path() == e2->library_path());
  int libraries = 0;
  for (const auto& f : fs::directory_iterator(cache.dir))  // main libraries (not u-dot candidates, *.udot-*.so)
    libraries += f.path().extension() == ".so" && f.path().filename().string().find(".udot-") == std::string::npos;
  CHECK(libraries == 1);
  CHECK(e2->parameters().size() == 0);  // the model's own parameters: none declared
  for (const Model* m : {&m1, &m2}) {
    GeneratedEngine& e = m == &m1 ? *e1 : *e2;
    GenericEngine g(*m);
    const State s = initial_state(*m);
    VecX a, b;
    e.udot(s.q, s.u, s.tau, a);
    g.udot(s.q, s.u, s.tau, b);
    CHECK((a - b).cwiseAbs().maxCoeff() <= 1e-12 * b.cwiseAbs().maxCoeff());
  }
  VecX a, b;
  const State s = initial_state(m1);
  e1->udot(s.q, s.u, s.tau, a);
  e2->udot(s.q, s.u, s.tau, b);
  CHECK((a - b).cwiseAbs().maxCoeff() > 1e-3);  // the values reached the code
}
