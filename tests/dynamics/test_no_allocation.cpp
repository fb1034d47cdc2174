// The generic engine evaluates from a workspace allocated once: after a
// warm-up call, u-dot, M, F, the reactions, energy and momentum allocate
// nothing on the heap (counted by interposing malloc for this test binary).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "tests/support/test_support.hpp"

namespace {
thread_local bool g_counting = false;
thread_local long g_allocations = 0;
}  // namespace

// Counting malloc itself catches Eigen's allocations (aligned_malloc calls
// malloc) as well as operator new's. glibc lets the executable interpose it.
extern "C" void* __libc_malloc(std::size_t);
extern "C" void* __libc_realloc(void*, std::size_t);
extern "C" void* __libc_calloc(std::size_t, std::size_t);
extern "C" void* malloc(std::size_t n) {
  if (g_counting) ++g_allocations;
  return __libc_malloc(n);
}
extern "C" void* realloc(void* p, std::size_t n) {
  if (g_counting) ++g_allocations;
  return __libc_realloc(p, n);
}
extern "C" void* calloc(std::size_t a, std::size_t b) {
  if (g_counting) ++g_allocations;
  return __libc_calloc(a, b);
}

using namespace kanegen;

TEST_CASE("generic engine: no heap allocation per evaluation", "[generic][allocation]") {
  for (const char* rel : {"models/explorer1_rigid.yaml", "models/branched_tree.yaml", "models/explorer1.yaml",
                          "tests/reference/v_flex_free/v_flex_free.yaml"}) {
    INFO(rel);
    const Model model = load_model(test::source_path(rel));
    GenericEngine engine(model);
    const State s = initial_state(model);
    VecX udot(model.nu), F(model.nu), qdot(model.nq);
    MatX M(model.nu, model.nu);
    std::vector<Reaction> R(model.bodies.size());
    // warm-up: sizes every output once
    engine.udot(s.q, s.u, s.tau, udot);
    engine.mass_matrix(s.q, M);
    engine.forcing(s.q, s.u, s.tau, F);
    engine.qdot(s.q, s.u, qdot);
    engine.reactions(s.q, s.u, udot, R);
    double sink = engine.energy(s.q, s.u).T + engine.momentum(s.q, s.u).H_N.norm();
    g_allocations = 0;
    g_counting = true;
    for (int k = 0; k < 3; ++k) {
      engine.udot(s.q, s.u, s.tau, udot);
      engine.mass_matrix(s.q, M);
      engine.forcing(s.q, s.u, s.tau, F);
      engine.qdot(s.q, s.u, qdot);
      engine.reactions(s.q, s.u, udot, R);
      const EnergyValues E = engine.energy(s.q, s.u);
      const MomentumValues P = engine.momentum(s.q, s.u);
      sink += E.T + E.V + P.p_N(0) + P.H_N(2);
    }
    g_counting = false;
    CHECK(g_allocations == 0);
    CHECK(std::isfinite(sink));
  }
}
