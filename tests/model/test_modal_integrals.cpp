// The modal integrals (modal_integrals.hpp) and the body terms built from them
// (body_inertia.hpp) against brute-force sums over the nodes: with node
// positions s_k = rho_k + Phi_k eta and A_k = [I, -s_k^x, Phi_k],
//   M_body = Sum m_k A_k^T A_k + blkdiag(0, I_rigid + Sum J_k, 0) (+ rigid part)
//   h_body = Sum A_k^T m_k (w x (w x s_k) + 2 w x Phi_k eta_dot) + [0; w x (J w); 0]
//   g_body = Sum A_k^T m_k g
// at random eta, eta_dot, w, including terms of second order in eta.
#include <catch2/catch.hpp>
#include <random>

#include "dynamics/body_inertia.hpp"
#include "model/model_loader.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

struct BruteForce {
  MatX M;
  VecX h, g;
};

BruteForce brute_force(const Body& b, const VecX& eta, const VecX& eta_dot, const Vec3& w, const Vec3& g_B) {
  const FlexibleData& f = *b.flex;
  const int m = f.modes();
  BruteForce r{MatX::Zero(6 + m, 6 + m), VecX::Zero(6 + m), VecX::Zero(6 + m)};
  auto add_point = [&](double mass, const Vec3& s, const MatX& Phi, const Vec3& b_acc) {
    MatX A = MatX::Zero(3, 6 + m);
    A.leftCols(3) = Mat3::Identity();
    A.middleCols(3, 3) = -skew<double>(s);
    if (Phi.cols()) A.rightCols(m) = Phi;
    r.M += mass * A.transpose() * A;
    r.h += A.transpose() * (mass * b_acc);
    r.g += A.transpose() * (mass * g_B);
  };
  // rigid part: a point at the com plus its central inertia
  const Vec3 c = b.rigid.com_B;
  add_point(b.rigid.mass, c, MatX::Zero(3, m), w.cross(w.cross(c)));
  Mat3 J = b.rigid.I_c_B;
  for (std::size_t k = 0; k < f.nodes.size(); ++k) {
    const MatX Phi = f.Phi.middleRows(3 * k, 3);
    const Vec3 s = f.nodes[k].rho_B + Phi * eta;
    const Vec3 v_el = Phi * eta_dot;
    add_point(f.nodes[k].mass, s, Phi, w.cross(w.cross(s)) + 2 * w.cross(v_el));
    J += f.nodes[k].J_B;
  }
  r.M.block(3, 3, 3, 3) += J;
  r.h.segment<3>(3) += w.cross(J * w);
  return r;
}

}  // namespace

TEST_CASE("modal integrals reproduce brute-force node sums, second order in eta included", "[modal][flexible]") {
  for (const char* rel : {"tests/reference/v_flex_free/v_flex_free.yaml", "tests/reference/v_flex/v_flex.yaml",
                          "models/spacecraft_arrays.yaml"}) {
    const Model model = load_model(test::source_path(rel));
    std::mt19937 rng(13);
    std::uniform_real_distribution<double> U(-1, 1);
    for (const Body& b : model.bodies) {
      if (!b.flex) continue;
      INFO(rel << " body " << b.name);
      const int m = b.n_modes();
      for (int trial = 0; trial < 5; ++trial) {
        VecX eta(m), eta_dot(m);
        for (int i = 0; i < m; ++i) eta(i) = 0.3 * U(rng), eta_dot(i) = U(rng);
        const Vec3 w(U(rng), U(rng), U(rng)), g_B(U(rng), U(rng), U(rng));
        MatX M(6 + m, 6 + m);
        VecX h(6 + m), g(6 + m);
        VecX Q[3][3];
        for (auto& row : Q)
          for (auto& v : row) v = VecX::Zero(m);
        compute_body_inertia<double>(b.integrals, eta, eta_dot, w, g_B, M, h, g, Q);
        const BruteForce bf = brute_force(b, eta, eta_dot, w, g_B);
        CHECK(test::rel_err(M, bf.M) < 1e-13);
        CHECK(test::rel_err(h, bf.h) < 1e-13);
        CHECK(test::rel_err(g, bf.g) < 1e-13);
        // and the eta-dependence is really exercised: M differs from M(eta = 0)
        MatX M0(6 + m, 6 + m);
        VecX h0(6 + m), g0(6 + m);
        const VecX zero = VecX::Zero(m);
        compute_body_inertia<double>(b.integrals, zero, eta_dot, w, g_B, M0, h0, g0, Q);
        CHECK((M - M0).norm() > 1e-6 * M.norm());
      }
    }
  }
}
