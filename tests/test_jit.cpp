// JIT plumbing: model hash, entry template, GeneratedEngine, compile cache,
// concurrency and compiler failures. Uses the hand-written stand-in header
// tests/data/generated/pendulum_handwritten.hpp (no generator needed); the
// generator-backed test runs only when generator/generate.hpp is on the
// include path (i.e. when the tests link the generator).
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

#include "generic_engine.hpp"
#include "jit.hpp"
#include "model_hash.hpp"
#include "model_loader.hpp"
#include "test_support.hpp"

#if __has_include("generate.hpp")
#include "generate.hpp"
#define KANEGEN_TEST_HAVE_GENERATOR 1
#endif

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
    return o;
  }
};

// The model of pendulum_handwritten.hpp (see the comment there).
constexpr double kM = 2.0, kL = 0.75, kIyy = 0.1, kG = 9.81, kK = 0.5, kC = 0.2, kRest = 0.1;

Model make_handwritten_pendulum() {
  Model m;
  m.name = "pendulum_handwritten";
  m.g_N = Vec3(0, 0, -kG);
  Body b;
  b.name = "bob";
  b.parent = -1;
  b.joint.type = JointType::revolute;
  b.joint.axis_J = Vec3::UnitY();
  b.joint.stiffness = kK;
  b.joint.damping = kC;
  b.joint.rest = kRest;
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

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The hand-written header with the model's hash and this build's version filled in.
std::string handwritten_header_text(const Model& model) {
  std::string text = slurp(test::source_path("tests/data/generated/pendulum_handwritten.hpp"));
  auto sub = [&](const std::string& from, const std::string& to) {
    for (std::size_t p = 0; (p = text.find(from, p)) != std::string::npos; p += to.size()) text.replace(p, from.size(), to);
  };
  sub("@MODEL_HASH@", model_hash(model));
  sub("@GENERATOR_VERSION@", KANEGEN_VERSION);
  return text;
}

fs::path write_handwritten_header(const fs::path& dir, const Model& model) {
  const fs::path p = dir / "pendulum_handwritten.hpp";
  std::ofstream(p) << handwritten_header_text(model);
  return p;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int count_entries(const fs::path& dir, const std::string& prefix) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind(prefix, 0) == 0) ++n;
  return n;
}

const char* kNs = "kanegen_gen::pendulum_handwritten";

void check_pendulum_numbers(GeneratedEngine& e) {
  const Model& model = e.model();
  GenericEngine generic(model);
  const double th = 0.37, w = -1.3, tau = 0.25;
  VecX q(1), u(1), t(1);
  q << th;
  u << w;
  t << tau;
  const double M0 = kM * kL * kL + kIyy;
  const double F0 = kM * kG * kL * std::cos(th) - kK * (th - kRest) - kC * w + tau;

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

  // reactions were not requested: NULL in the table, a clear error here.
  CHECK(e.api().reactions == nullptr);
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
  CHECK(differs([](Model& m) { m.bodies[0].joint.stiffness += 1e-9; }));
  CHECK(differs([](Model& m) { m.bodies[0].joint.damping += 1e-9; }));
  CHECK(differs([](Model& m) { m.bodies[0].joint.rest += 1e-9; }));
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
}

TEST_CASE("generated engine refuses a table that does not match the model", "[jit]") {
  const Model model = make_handwritten_pendulum();
  const std::string hash = model_hash(model);
  auto qd = +[](const double*, const double* u, double* o) { o[0] = u[0]; };
  auto mm = +[](const double*, double* M) { M[0] = 1.0; };
  auto fo = +[](const double*, const double*, const double*, double* F) { F[0] = 0.0; };
  auto ud = +[](const double*, const double*, const double*, double*) { return 1; };
  KanegenGeneratedApi api{KANEGEN_GENERATED_API_VERSION, "pendulum_handwritten", hash.c_str(), KANEGEN_VERSION,
                          1, 1, 1, qd, mm, fo, ud, nullptr, nullptr, nullptr, nullptr};
  {
    GeneratedEngine e(model, &api);
    VecX q = VecX::Zero(1), u = VecX::Zero(1), out;
    CHECK_THROWS_AS(e.udot(q, u, u, out), SingularMassMatrix);
    CHECK_THROWS_WITH(e.energy(q, u), Catch::Contains("without 'energy' output"));
    CHECK_THROWS_WITH(e.momentum(q, u), Catch::Contains("without 'momentum' output"));
    MatX J;
    CHECK_FALSE(e.jacobian(q, u, u, J));
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
  bad = api;
  bad.generator_version = "0.0.0-other";
  CHECK_THROWS_WITH(GeneratedEngine(model, &bad), Catch::Contains("generated by kanegen 0.0.0-other"));
  CHECK_THROWS(GeneratedEngine(model, nullptr));
}

TEST_CASE("compile_and_load: hand-written header, cache hit, concurrent loads", "[jit]") {
  TempCache cache;
  const Model model = make_handwritten_pendulum();
  const fs::path header = write_handwritten_header(cache.dir, model);
  const JitOptions opts = cache.options();
  const std::string so = (cache.dir / "pendulum_handwritten-test.so").string();

  // Two threads race on the same uncached library: both must succeed.
  std::unique_ptr<GeneratedEngine> e1, e2;
  std::string err1, err2;
  const auto t0 = std::chrono::steady_clock::now();
  auto load = [&](std::unique_ptr<GeneratedEngine>& e, std::string& err) {
    try {
      e = compile_and_load(model, header.string(), kNs, so, opts);
    } catch (const std::exception& ex) {
      err = ex.what();
    }
  };
  std::thread th1(load, std::ref(e1), std::ref(err1));
  std::thread th2(load, std::ref(e2), std::ref(err2));
  th1.join();
  th2.join();
  const double compile_s = seconds_since(t0);
  INFO("thread errors: " << err1 << " | " << err2);
  REQUIRE(e1);
  REQUIRE(e2);
  REQUIRE(fs::exists(so));
  CHECK(count_entries(cache.dir, ".tmp-") == 0);  // nothing half-written left
  CHECK(e1->name() == "generated");
  CHECK(e1->library_path() == so);
  check_pendulum_numbers(*e1);
  check_pendulum_numbers(*e2);

  // Second load: a cache hit, at once, the library untouched.
  struct stat st0 {};
  REQUIRE(stat(so.c_str(), &st0) == 0);
  e1.reset();
  e2.reset();
  const auto t1 = std::chrono::steady_clock::now();
  auto e3 = compile_and_load(model, header.string(), kNs, so, opts);
  const double hit_s = seconds_since(t1);
  struct stat st1 {};
  REQUIRE(stat(so.c_str(), &st1) == 0);
  CHECK(hit_s < 0.2);
  CHECK(st1.st_mtim.tv_sec == st0.st_mtim.tv_sec);
  CHECK(st1.st_mtim.tv_nsec == st0.st_mtim.tv_nsec);
  CHECK(st1.st_ino == st0.st_ino);
  check_pendulum_numbers(*e3);
  WARN(fmt::format("hand-written pendulum: 2 concurrent compiles {:.2f} s, cache-hit load {:.4f} s", compile_s, hit_s));

  // The same library against a model that differs: refused with a clear message.
  Model other = model;
  other.bodies[0].rigid.mass = 3.0;
  CHECK_THROWS_WITH(load_generated_library(other, so), Catch::Contains("different version of the model"));
}

TEST_CASE("compile_and_load from two processes at once", "[jit]") {
  TempCache cache;
  const Model model = make_handwritten_pendulum();
  const fs::path header = write_handwritten_header(cache.dir, model);
  const JitOptions opts = cache.options();
  const std::string so = (cache.dir / "pendulum_handwritten-proc.so").string();
  std::fflush(nullptr);
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    int rc = 1;
    try {
      auto e = compile_and_load(model, header.string(), kNs, so, opts);
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
    e = compile_and_load(model, header.string(), kNs, so, opts);
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
  std::string text = handwritten_header_text(model);
  const std::string needle = "qd[0] = u[0];";
  const auto pos = text.find(needle);
  REQUIRE(pos != std::string::npos);
  text.replace(pos, needle.size(), "qd[0] = u[0] +* ;  // kanegen-test-syntax-error");
  const fs::path header = cache.dir / "broken.hpp";
  std::ofstream(header) << text;
  JitOptions opts = cache.options();
  opts.compiler = "c++";
  const std::string so = (cache.dir / "broken-test.so").string();
  try {
    compile_and_load(model, header.string(), kNs, so, opts);
    FAIL("no JitError");
  } catch (const JitError& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(what.find("c++ -std=c++20 -fPIC -O2 -DKANEGEN_PART=") != std::string::npos);  // the failing part's command
    CHECK(what.find("broken.hpp") != std::string::npos);
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
  CHECK_THROWS_AS(compile_and_load(model, header.string(), kNs, so, opts), JitError);
}

TEST_CASE("jit_load_with: generate, compile, cache by model and flags", "[jit]") {
  TempCache cache;
  const Model model = make_handwritten_pendulum();
  int generated = 0;
  HeaderGenerator fake = [&](const Model& m) {
    ++generated;
    return handwritten_header_text(m);
  };
  const JitOptions opts = cache.options();
  const std::string path = jit_library_path(model, opts);
  CHECK(fs::path(path).parent_path() == cache.dir);
  CHECK(fs::path(path).filename().string().rfind("pendulum_handwritten-", 0) == 0);
  CHECK(fs::path(path).extension() == ".so");

  auto e = jit_load_with(model, opts, fake);
  CHECK(generated == 1);
  CHECK(e->library_path() == path);
  check_pendulum_numbers(*e);
  auto e2 = jit_load_with(model, opts, fake);
  CHECK(generated == 1);  // hit: no generation

  // Different flags or a different model: a different library.
  JitOptions o2 = opts;
  o2.flags = "-O1 -std=c++20 -fPIC -shared";
  CHECK(jit_library_path(model, o2) != path);
  Model other = model;
  other.bodies[0].joint.damping = 0.3;
  CHECK(jit_library_path(other, opts) != path);
  CHECK(jit_cache_key(model, opts) == jit_cache_key(make_handwritten_pendulum(), opts));

  // Defaults come from the environment.
  JitOptions none;
  ::setenv("KANEGEN_CACHE_DIR", cache.dir.c_str(), 1);
  CHECK(resolved(none).cache_dir == cache.dir.string());
  ::unsetenv("KANEGEN_CACHE_DIR");
  CHECK(resolved(none).flags == "-O2 -std=c++20 -fPIC -shared");
}

#ifdef KANEGEN_TEST_HAVE_GENERATOR
TEST_CASE("jit_load of v_double3d matches the generic engine", "[jit][generator]") {
  TempCache cache;
  const Model model = load_model(test::source_path("tests/reference/v_double3d/v_double3d.yaml"));
  const auto tc = std::chrono::steady_clock::now();
  auto e = jit_load(model, cache.options());
  const double miss_s = seconds_since(tc);
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
  // Second load: a cache hit.
  const auto t0 = std::chrono::steady_clock::now();
  auto e2 = jit_load(model, cache.options());
  const double hit_s = seconds_since(t0);
  CHECK(hit_s < 0.2);
  WARN(fmt::format("v_double3d: generate + compile {:.2f} s, cache-hit load {:.4f} s", miss_s, hit_s));
}
#endif
