#include "model/modal_integrals.hpp"

#include <algorithm>
#include <array>
#include <vector>

#include "model/model.hpp"

namespace kanegen {

static Eigen::Matrix3d point_inertia(double m, const Eigen::Vector3d& r) {
  return m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
}

namespace {

/// I.rich of compute_mass_integrals (modal_integrals.hpp, RichNodeSums): empty (nodes = 0, no storage) for a
/// body without rich nodes of mass; Y1 and Y2 (m^2 (m + 1) / 2 and m^2 (m + 1)^2 / 4 numbers) only up to
/// RichNodeSums::kMaxModesModalMass modes (and Y with them), and only their entries i <= l.
void add_rich_node_sums(const FlexibleData& flex, RichNodeSums& r) {
  const int m = flex.modes();
  std::vector<int> rich;
  for (int k = 0; k < static_cast<int>(flex.nodes.size()); ++k)
    if (flex.node_is_rich(k) && flex.nodes[static_cast<std::size_t>(k)].mass != 0.0) rich.push_back(k);
  if (rich.empty()) return;
  r.B = Eigen::MatrixXd::Zero(3, m);
  for (auto& G : r.G) G = Eigen::MatrixXd::Zero(m, m);
  r.Y = Eigen::MatrixXd::Zero(m, m);
  const bool modal_mass = m <= RichNodeSums::kMaxModesModalMass;
  if (modal_mass) {
    r.Y1.assign(static_cast<std::size_t>(m * m), Eigen::VectorXd());
    r.Y2.assign(static_cast<std::size_t>(m * m), Eigen::MatrixXd());
    for (int i = 0; i < m; ++i)
      for (int l = i; l < m; ++l) {
        r.Y1[static_cast<std::size_t>(i * m + l)] = Eigen::VectorXd::Zero(m);
        r.Y2[static_cast<std::size_t>(i * m + l)] = Eigen::MatrixXd::Zero(m, m);
      }
  }
  std::array<Eigen::MatrixXd, 3> Gk;  // Gamma_k^a, upper triangle mirrored
  for (const int k : rich) {
    const double mk = flex.nodes[static_cast<std::size_t>(k)].mass;
    const auto Phi = flex.Phi.middleRows(3 * k, 3);  // 3 x m
    ++r.nodes;
    r.mass += mk;
    r.S0 += mk * flex.nodes[static_cast<std::size_t>(k)].rho_B;
    r.B += mk * Phi;
    if (modal_mass) r.Y.noalias() += mk * Phi.transpose() * Phi;
    for (int a = 0; a < 3; ++a) {
      if (!flex.has_second_order(k) || flex.Gamma[k][a].size() == 0) continue;
      r.G[a].triangularView<Eigen::Upper>() += mk * flex.Gamma[k][a];  // mirrored below
      if (!modal_mass) continue;
      Gk[a] = flex.Gamma[k][a].selfadjointView<Eigen::Upper>();
      for (int i = 0; i < m; ++i)
        for (int l = i; l < m; ++l) {
          const std::size_t il = static_cast<std::size_t>(i * m + l);
          r.Y1[il] += mk * (Phi(a, i) * Gk[a].row(l).transpose() + Phi(a, l) * Gk[a].row(i).transpose());
          r.Y2[il].noalias() += (0.5 * mk) * (Gk[a].row(i).transpose() * Gk[a].row(l) +
                                              Gk[a].row(l).transpose() * Gk[a].row(i));
        }
    }
  }
  for (auto& G : r.G) G = G.selfadjointView<Eigen::Upper>();
}

}  // namespace

BodyMassIntegrals compute_mass_integrals(const RigidPart& rigid, const FlexibleData* flex) {
  BodyMassIntegrals I;
  I.m = flex ? flex->modes() : 0;
  const int m = I.m;
  I.mass = rigid.mass;
  I.S0 = rigid.mass * rigid.com_B;
  I.J0 = rigid.I_c_B + point_inertia(rigid.mass, rigid.com_B);
  I.B = Eigen::MatrixXd::Zero(3, m);
  I.Y = Eigen::MatrixXd::Zero(m, m);
  for (auto& row : I.Prf)
    for (auto& v : row) v = Eigen::VectorXd::Zero(m);
  for (auto& row : I.Pff)
    for (auto& M : row) M = Eigen::MatrixXd::Zero(m, m);
  I.rich = RichNodeSums{};
  if (!flex) return I;
  add_rich_node_sums(*flex, I.rich);
  // Plain nodes gathered so that the sums over nodes are matrix products
  // (O(nodes m^2) in GEMM rather than node by node: 2,000 nodes x 500 modes
  // in well under a second).
  std::vector<Eigen::Index> plain;
  for (std::size_t k = 0; k < flex->nodes.size(); ++k) {
    if (flex->node_is_rich(static_cast<int>(k))) continue;  // handled node by node (body_inertia.hpp)
    plain.push_back(static_cast<Eigen::Index>(k));
  }
  const auto n = static_cast<Eigen::Index>(plain.size());
  Eigen::VectorXd w(n);                      // node masses
  Eigen::MatrixXd rho(n, 3);                 // node positions (body frame)
  std::array<Eigen::MatrixXd, 3> X;          // X[a](k, :) = Phi(3 k + a, :)
  std::array<Eigen::MatrixXd, 3> WX;         // diag(w) X[a]
  for (int a = 0; a < 3; ++a) X[a].resize(n, m);
  for (Eigen::Index r = 0; r < n; ++r) {
    const ModalNode& node = flex->nodes[static_cast<std::size_t>(plain[r])];
    w(r) = node.mass;
    rho.row(r) = node.rho_B.transpose();
    for (int a = 0; a < 3; ++a) X[a].row(r) = flex->Phi.row(3 * plain[r] + a);
    I.mass += node.mass;
    I.S0 += node.mass * node.rho_B;
    I.J0 += point_inertia(node.mass, node.rho_B);  // a plain node has no rotary inertia
  }
  for (int a = 0; a < 3; ++a) {
    WX[a] = w.asDiagonal() * X[a];
    I.B.row(a) = w.transpose() * X[a];
  }
  for (int a = 0; a < 3; ++a) {
    for (int b = a; b < 3; ++b) {
      I.Pff[a][b] = X[a].transpose() * WX[b];
      if (b != a) I.Pff[b][a] = I.Pff[a][b].transpose();
    }
    const Eigen::VectorXd w_rho_a = w.cwiseProduct(rho.col(a));
    for (int b = 0; b < 3; ++b) I.Prf[a][b] = X[b].transpose() * w_rho_a;
  }
  I.Y = I.Pff[0][0] + I.Pff[1][1] + I.Pff[2][2];
  return I;
}

}  // namespace kanegen
