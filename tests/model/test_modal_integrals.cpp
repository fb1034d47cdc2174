// The body terms (dynamics/body_inertia.hpp: mass integrals for the plain
// nodes, node-by-node terms for nodes with rotary inertia or foreshortening)
// against brute-force sums over the nodes, written element by element from
// the definitions of dynamics.md: node positions s_k(eta) = rho_k + Phi_k eta
// + 1/2 gamma_k(eta), whose derivative Phi~_k and second derivative along
// eta_dot are taken here by central differences (exact for a quadratic), and
// node frames C(Psi_k eta) carrying J_k, whose rate term is differenced too:
//   M_body = Sum m_k A_k^T A_k + Omega_k^T J'_k Omega_k (+ rigid part),
//   A_k = [I, -s_k^x, Phi~_k], Omega_k = [0, I, H_k], J'_k = C J_k C^T
//   h_body = Sum m_k A_k^T b_k + Omega_k^T (J'_k beta_k + w_k x J'_k w_k)
//   g_body = Sum m_k A_k^T g
// at random eta, eta_dot, w, including terms of second order in eta.
#include <catch2/catch.hpp>
#include <random>

#include "dynamics/body_inertia.hpp"
#include "model/rotation.hpp"
#include "engine/load_model.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

struct BruteForce {
  MatX M;
  VecX h, g;
};

/// Node k's displaced position rho_k + Phi_k e + 1/2 gamma_k(e), from dynamics.md's definition.
Vec3 node_position_at(const FlexibleData& f, std::size_t k, const VecX& e) {
  Vec3 s = f.nodes[k].rho_B + f.Phi.middleRows(3 * static_cast<Eigen::Index>(k), 3) * e;
  if (f.has_second_order(static_cast<int>(k)))
    for (int a = 0; a < 3; ++a)
      if (f.Gamma[k][a].size()) s(a) += 0.5 * e.dot(f.Gamma[k][a] * e);
  return s;
}

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
  r.M.block(3, 3, 3, 3) += b.rigid.I_c_B;
  r.h.segment<3>(3) += w.cross(b.rigid.I_c_B * w);
  for (std::size_t k = 0; k < f.nodes.size(); ++k) {
    auto position = [&](const VecX& e) { return node_position_at(f, k, e); };
    const Vec3 s = position(eta);
    // Phi~ = ds/deta and the second derivative along eta_dot: central differences,
    // exact (to rounding) for the quadratic s(eta).
    const double eps = 1.0;
    MatX Phi_t(3, m);
    for (int i = 0; i < m; ++i) {
      VecX ep = eta, em = eta;
      ep(i) += eps, em(i) -= eps;
      Phi_t.col(i) = (position(ep) - position(em)) / (2 * eps);
    }
    const Vec3 s_dd = position(eta + eps * eta_dot) - 2 * s + position(eta - eps * eta_dot);
    const Vec3 v_rel = Phi_t * eta_dot;
    add_point(f.nodes[k].mass, s, Phi_t, w.cross(w.cross(s)) + 2 * w.cross(v_rel) + s_dd / (eps * eps));
    const Mat3& J = f.nodes[k].J_B;
    if (J.isZero(0.0)) continue;
    // node frame C(Psi eta) with angular velocity w + H eta_dot; H's rate by differences
    const MatX Psi = f.Psi.middleRows(3 * k, 3);
    auto H_of = [&](const VecX& e) {
      const Vec3 g = Psi * e / 2;
      return MatX((Mat3::Identity() + skew<double>(g)) * Psi / (1 + g.dot(g)));
    };
    const Mat3 C = rodrigues_R<double>(Vec3(Psi * eta));
    const Mat3 Jp = C * J * C.transpose();
    const MatX H = H_of(eta);
    const double h = 1e-5;
    const Vec3 Hdot_eta_dot = (H_of(eta + h * eta_dot) - H_of(eta - h * eta_dot)) * eta_dot / (2 * h);
    MatX Om = MatX::Zero(3, 6 + m);
    Om.middleCols(3, 3) = Mat3::Identity();
    Om.rightCols(m) = H;
    const Vec3 w_k = w + H * eta_dot;
    const Vec3 Hed = H * eta_dot;
    const Vec3 beta = w.cross(Hed) + Hdot_eta_dot;
    r.M += Om.transpose() * Jp * Om;
    r.h += Om.transpose() * (Jp * beta + w_k.cross(Jp * w_k));
  }
  return r;
}

/// The engine's body terms: integrals plus the rich nodes one by one.
void body_terms(const Body& b, const VecX& eta, const VecX& eta_dot, const Vec3& w, const Vec3& g_B, MatX& M, VecX& h,
                VecX& g) {
  const int m = b.n_modes();
  VecX Q[3][3];
  for (auto& row : Q)
    for (auto& v : row) v = VecX::Zero(m);
  compute_body_inertia<double>(b.integrals, eta, eta_dot, w, g_B, M, h, g, Q);
  Vec3 S = integrated_first_moment<double>(b.integrals, eta);
  Eigen::Matrix<double, 3, Eigen::Dynamic> Pt(3, m), H(3, m), JH(3, m);
  VecX tmp(m);
  for (int k : b.rich_nodes) add_node_terms<double>(*b.flex, k, eta, eta_dot, w, g_B, M, h, g, S, Pt, H, JH, tmp);
}

}  // namespace

TEST_CASE("modal integrals reproduce brute-force node sums, second order in eta included", "[modal][flexible]") {
  for (const char* rel : {"tests/reference/v_flex_free/v_flex_free.yaml", "tests/reference/v_flex/v_flex.yaml",
                          "tests/reference/v_spinup/v_spinup.yaml", "models/spacecraft_arrays.yaml",
                          "models/explorer1.yaml"}) {
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
        body_terms(b, eta, eta_dot, w, g_B, M, h, g);
        const BruteForce bf = brute_force(b, eta, eta_dot, w, g_B);
        // Differenced rates of a node frame carry O(1e-10) truncation error.
        bool rotary = false;
        for (const auto& n : b.flex->nodes) rotary = rotary || !n.J_B.isZero(0.0);
        const double tol_h = rotary ? 1e-8 : 1e-13;
        CHECK(test::rel_err(M, bf.M) < 1e-13);
        CHECK(test::rel_err(h, bf.h) < tol_h);
        CHECK(test::rel_err(g, bf.g) < 1e-13);
        // and the eta-dependence is really exercised: M differs from M(eta = 0)
        MatX M0(6 + m, 6 + m);
        VecX h0(6 + m), g0(6 + m);
        body_terms(b, VecX::Zero(m), eta_dot, w, g_B, M0, h0, g0);
        CHECK((M - M0).norm() > 1e-6 * M.norm());
      }
    }
  }
}

TEST_CASE("the rich nodes' sums of degree 2 in eta (RichNodeSums) equal the sums over the nodes", "[modal][flexible]") {
  // What the generated code evaluates once per body instead of node by node (issue 38, item 2): the rich
  // nodes' mass, first moment, participation Sum m Phi~, modal mass Sum m Phi~_i . Phi~_l and the
  // remainder Sum m eta_dot^T Gamma^a eta_dot, against the nodes' positions differenced (exact for a quadratic).
  int bodies_with_foreshortening = 0;
  for (const char* rel : {"models/spacecraft_arrays.yaml", "models/explorer1.yaml", "tests/reference/v_spinup/v_spinup.yaml"}) {
    const Model model = load_model(test::source_path(rel));
    std::mt19937 rng(29);
    std::uniform_real_distribution<double> U(-1, 1);
    for (const Body& b : model.bodies) {
      if (!b.flex || b.rich_nodes.empty()) continue;
      INFO(rel << " body " << b.name);
      const FlexibleData& f = *b.flex;
      const RichNodeSums& R = b.integrals.rich;
      REQUIRE(R.nodes > 0);  // these models' rich nodes have mass
      REQUIRE_FALSE(R.Y2.empty());
      const int m = f.modes();
      bool second_order = false;
      for (int k : b.rich_nodes) second_order = second_order || f.has_second_order(k);
      bodies_with_foreshortening += second_order;
      for (int trial = 0; trial < 4; ++trial) {
        VecX eta(m), eta_dot(m);
        for (int i = 0; i < m; ++i) eta(i) = 0.5 * U(rng), eta_dot(i) = U(rng);
        double mass = 0;
        Vec3 S = Vec3::Zero(), dd = Vec3::Zero();
        MatX Bt = MatX::Zero(3, m), Y = MatX::Zero(m, m);
        for (int k : b.rich_nodes) {
          auto position = [&](const VecX& e) { return node_position_at(f, static_cast<std::size_t>(k), e); };
          const double mk = f.nodes[k].mass;
          MatX Pt(3, m);
          for (int i = 0; i < m; ++i) {
            VecX ep = eta, em = eta;
            ep(i) += 1, em(i) -= 1;
            Pt.col(i) = (position(ep) - position(em)) / 2;
          }
          mass += mk;
          S += mk * position(eta);
          Bt += mk * Pt;
          Y += mk * Pt.transpose() * Pt;
          dd += mk * (position(eta + eta_dot) - 2 * position(eta) + position(eta - eta_dot));
        }
        Vec3 S_sums = R.S0 + R.B * eta, dd_sums;
        MatX Bt_sums = R.B, Y_sums = R.Y;
        for (int a = 0; a < 3; ++a) {
          S_sums(a) += 0.5 * eta.dot(R.G[a] * eta);
          Bt_sums.row(a) += (R.G[a] * eta).transpose();
          dd_sums(a) = eta_dot.dot(R.G[a] * eta_dot);
        }
        for (int i = 0; i < m; ++i)
          for (int l = i; l < m; ++l)  // stored for i <= l
            Y_sums(l, i) = Y_sums(i, l) += R.Y1[i * m + l].dot(eta) + eta.dot(R.Y2[i * m + l] * eta);
        CHECK(R.mass == Approx(mass).epsilon(1e-14));
        CHECK(test::rel_err(S_sums, S) < 1e-13);
        CHECK(test::rel_err(Bt_sums, Bt) < 1e-13);
        CHECK(test::rel_err(Y_sums, Y) < 1e-13);
        CHECK((dd_sums - dd).norm() <= 1e-13 * std::max(1.0, dd.norm()));
        // the second-order part is exercised: Y moves with eta where a node foreshortens
        if (second_order) CHECK((Y - R.Y).norm() > 1e-6 * Y.norm());
      }
    }
  }
  CHECK(bodies_with_foreshortening >= 3);
}

TEST_CASE("the rich nodes' sums take no storage without rich nodes, and no modal-mass block beyond 16 modes",
          "[modal][flexible]") {
  // a body of many modes must load in the memory of its mode shapes, not m^4 (docs/limits.md: 500 modes)
  for (const char* rel : {"models/spacecraft_arrays.yaml", "models/clamped_beam.yaml"}) {
    const Model model = load_model(test::source_path(rel));
    for (const Body& b : model.bodies) {
      if (!b.flex) continue;
      INFO(rel << " body " << b.name);
      const RichNodeSums& R = b.integrals.rich;
      bool rich_mass = false;
      for (int k : b.rich_nodes) rich_mass = rich_mass || b.flex->nodes[k].mass != 0.0;
      CHECK((R.nodes > 0) == rich_mass);
      if (!rich_mass) CHECK((R.B.size() == 0 && R.Y.size() == 0 && R.Y1.empty() && R.Y2.empty()));
    }
  }
  FlexibleData f;
  const int m = RichNodeSums::kMaxModesModalMass + 1, nodes = 3;
  f.Phi = MatX::Random(3 * nodes, m);
  f.Psi = MatX::Zero(3 * nodes, m);
  f.Gamma.resize(nodes);
  for (int k = 0; k < nodes; ++k) {
    ModalNode n;
    n.id = k + 1;
    n.mass = 1.0 + k;
    n.rho_B = Vec3(0, 0.5 * k, 0);
    f.nodes.push_back(n);
    const MatX G = MatX::Random(m, m);
    f.Gamma[k][1] = G + G.transpose();
  }
  RigidPart rigid;
  const BodyMassIntegrals I = compute_mass_integrals(rigid, &f);
  CHECK(I.rich.nodes == nodes);
  CHECK(I.rich.mass == Approx(6.0));
  CHECK(I.rich.Y1.empty());
  CHECK(I.rich.Y2.empty());
  CHECK(test::rel_err(I.rich.G[1], MatX(1.0 * (f.Gamma[0][1]) + 2.0 * f.Gamma[1][1] + 3.0 * f.Gamma[2][1])) < 1e-14);
}
