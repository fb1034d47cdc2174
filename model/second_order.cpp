#include "model/second_order.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <stdexcept>
#include <vector>

namespace kanegen {

namespace {

/// Integral over an element of length l of w_i'(s).w_j'(s), w the cubic
/// Hermite interpolation of end values (da, sa, db, sb): deflections d and
/// slopes s (3-vectors). 3-point Gauss-Legendre: the integrand is a quartic.
double slope_product(double l, const Vec3 (&wi)[4], const Vec3 (&wj)[4]) {
  static const double xg[3] = {0.5 - 0.5 * std::sqrt(0.6), 0.5, 0.5 + 0.5 * std::sqrt(0.6)};
  static const double wg[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
  double sum = 0.0;
  for (int g = 0; g < 3; ++g) {
    const double x = xg[g];
    const double dN[4] = {-6 * x + 6 * x * x, l * (1 - 4 * x + 3 * x * x), 6 * x - 6 * x * x, l * (-2 * x + 3 * x * x)};
    Vec3 a = Vec3::Zero(), b = Vec3::Zero();
    for (int k = 0; k < 4; ++k) a += dN[k] * wi[k], b += dN[k] * wj[k];
    sum += wg[g] * a.dot(b);
  }
  return sum / l;
}

}  // namespace

void compute_chain_second_order(FlexibleData& flex) {
  const int n = static_cast<int>(flex.nodes.size()), m = flex.modes();
  if (n < 2) throw std::invalid_argument("fewer than two nodes: no chain to follow");
  double size = 0.0;
  for (const auto& nd : flex.nodes) size = std::max(size, nd.rho_B.norm());
  // The root: the node at the body origin.
  int root = -1;
  for (int k = 0; k < n; ++k)
    if (flex.nodes[k].rho_B.norm() <= 1e-9 * size) root = k;
  if (root < 0)
    throw std::invalid_argument("no node at the body origin; expected the chain to start at the clamp (a node at [0, 0, 0])");
  // Neighbours: nodes closer than 1.5 times either one's nearest distance (a
  // graded mesh stays connected; a branch gives a node three neighbours).
  std::vector<double> nearest(n, std::numeric_limits<double>::infinity());
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if (i != j) nearest[i] = std::min(nearest[i], (flex.nodes[i].rho_B - flex.nodes[j].rho_B).norm());
  std::vector<std::vector<int>> nb(n);
  for (int i = 0; i < n; ++i) {
    if (!(nearest[i] > 1e-12 * size))
      throw std::invalid_argument(fmt::format("node {} coincides with another node; expected distinct nodes along a chain",
                                              flex.nodes[i].id));
    for (int j = 0; j < n; ++j)
      if (i != j && (flex.nodes[i].rho_B - flex.nodes[j].rho_B).norm() <= 1.5 * std::max(nearest[i], nearest[j]))
        nb[i].push_back(j);
  }
  auto not_a_chain = [&](const std::string& why) {
    return std::invalid_argument("the nodes do not form a chain from the body origin: " + why +
                                 "; expected a boom- or antenna-like chain of nodes starting at the origin, or "
                                 "second_order data from the FEA (docs/second_order.md)");
  };
  for (int i = 0; i < n; ++i)
    if (nb[i].size() > 2 || (i == root && nb[i].size() != 1))
      throw not_a_chain(fmt::format("node {} has {} neighbours (a branch{})", flex.nodes[i].id, nb[i].size(),
                                    i == root ? ", or the origin inside the chain" : ""));
  std::vector<int> chain{root};
  for (int prev = -1, at = root; static_cast<int>(chain.size()) < n;) {
    int next = -1;
    for (int j : nb[at])
      if (j != prev) next = j;
    if (next < 0) throw not_a_chain(fmt::format("node {} is not connected to the chain", flex.nodes[at].id));
    if (std::find(chain.begin(), chain.end(), next) != chain.end())
      throw not_a_chain(fmt::format("node {} closes a loop", flex.nodes[next].id));
    chain.push_back(next);
    prev = at, at = next;
  }
  flex.Gamma.assign(n, {});
  MatX acc_sum[3] = {MatX::Zero(m, m), MatX::Zero(m, m), MatX::Zero(m, m)};
  for (int e = 0; e + 1 < n; ++e) {
    const int a = chain[e], b = chain[e + 1];
    const Vec3 d = flex.nodes[b].rho_B - flex.nodes[a].rho_B;
    const double l = d.norm();
    const Vec3 t = d / l;
    const Mat3 across = Mat3::Identity() - t * t.transpose();
    MatX I = MatX::Zero(m, m);
    std::vector<std::array<Vec3, 4>> ends(m);
    for (int i = 0; i < m; ++i) {
      ends[i][0] = across * flex.Phi.block<3, 1>(3 * a, i);
      ends[i][1] = flex.Psi.block<3, 1>(3 * a, i).cross(t);
      ends[i][2] = across * flex.Phi.block<3, 1>(3 * b, i);
      ends[i][3] = flex.Psi.block<3, 1>(3 * b, i).cross(t);
    }
    for (int i = 0; i < m; ++i)
      for (int j = i; j < m; ++j) {
        const Vec3 wi[4] = {ends[i][0], ends[i][1], ends[i][2], ends[i][3]};
        const Vec3 wj[4] = {ends[j][0], ends[j][1], ends[j][2], ends[j][3]};
        I(i, j) = I(j, i) = slope_product(l, wi, wj);
      }
    for (int ax = 0; ax < 3; ++ax) {
      acc_sum[ax] -= t(ax) * I;
      if (!acc_sum[ax].isZero(0.0)) flex.Gamma[b][ax] = acc_sum[ax];
    }
  }
  // Exact zeros stay exact (an axis the chain never runs along has no data).
  for (auto& G : flex.Gamma)
    for (auto& g : G)
      if (g.size() && g.isZero(0.0)) g.resize(0, 0);
}

}  // namespace kanegen
