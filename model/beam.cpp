// Euler–Bernoulli cantilever, lumped masses (beam.hpp).
//
// Nodes k = 0..n at s_k = k h along the beam direction d (h = L/n); node 0 is
// clamped at the body origin. Element mass mu h is lumped half to each end, so
// the nodes carry exactly the beam's mass (node 0 rigidly). Per free node the
// degrees of freedom are the transverse displacements w1, w2 along
// t1 = n1 x d, t2 = n2 x d (n1, n2 the normal axes in cyclic order), the
// bending rotations th1, th2 about n1, n2 (th_i = w_i'), and, with EA, the
// axial displacement. The lumped nodes have no rotary inertia, so the
// rotations are condensed statically (exact for this mass model); torsion
// carries no inertia and therefore no modes (GJ is accepted, it only
// stiffens). Shapes are mass-normalized: sum_k m_k t_k.t_k = 1.
#include "model/beam.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace kanegen {

namespace {

struct BeamMode {
  double lambda;   // omega^2
  int kind;        // 0, 1: bending with deflection along t1, t2; 2: axial
  VecX w;          // n translations (free nodes 1..n), mass-normalized
  VecX th;         // n bending rotations (empty for axial)
};

/// Modes of one decoupled problem: bending in one plane (stiffness EI) or,
/// with bending = false, axial (stiffness EA). Node masses m(1..n).
void solve_plane(bool bending, double EIorEA, double h, int n, const VecX& m, int kind, std::vector<BeamMode>& out) {
  MatX Ktt = MatX::Zero(n, n);
  MatX Ktr = MatX::Zero(n, n), Krr = MatX::Zero(n, n);
  if (bending) {
    const double c = EIorEA / (h * h * h);
    const double ke[4][4] = {{12, 6 * h, -12, 6 * h},
                             {6 * h, 4 * h * h, -6 * h, 2 * h * h},
                             {-12, -6 * h, 12, -6 * h},
                             {6 * h, 2 * h * h, -6 * h, 4 * h * h}};
    for (int e = 0; e < n; ++e) {
      // element from node e to e + 1, dofs (w_e, th_e, w_e+1, th_e+1); node 0 clamped.
      // Free node k has index k - 1 in both the w and the th block.
      const int idx[4] = {e - 1, e - 1, e, e};
      const bool rot[4] = {false, true, false, true};
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
          if (idx[a] < 0 || idx[b] < 0) continue;
          const double v = c * ke[a][b];
          if (!rot[a] && !rot[b]) Ktt(idx[a], idx[b]) += v;
          if (!rot[a] && rot[b]) Ktr(idx[a], idx[b]) += v;
          if (rot[a] && rot[b]) Krr(idx[a], idx[b]) += v;
        }
    }
  } else {
    const double c = EIorEA / h;
    for (int e = 0; e < n; ++e) {
      Ktt(e, e) += c;
      if (e > 0) {
        Ktt(e - 1, e - 1) += c;
        Ktt(e - 1, e) -= c;
        Ktt(e, e - 1) -= c;
      }
    }
  }
  MatX G;  // th = -G w (static condensation: the lumped nodes have no rotary inertia)
  MatX Kc = Ktt;
  if (bending) {
    const Eigen::LLT<MatX> Lrr(Krr);
    if (Lrr.info() != Eigen::Success) throw std::runtime_error("singular rotational stiffness");
    G = Lrr.solve(Ktr.transpose());
    Kc -= Ktr * G;
  }
  const VecX s = m.cwiseSqrt().cwiseInverse();
  MatX A = s.asDiagonal() * Kc * s.asDiagonal();
  A = 0.5 * (A + A.transpose());
  Eigen::SelfAdjointEigenSolver<MatX> es(A);
  if (es.info() != Eigen::Success) throw std::runtime_error("eigenvalue problem failed");
  for (int j = 0; j < n; ++j) {
    BeamMode md;
    md.lambda = std::max(es.eigenvalues()(j), 0.0);
    md.kind = kind;
    md.w = s.asDiagonal() * es.eigenvectors().col(j);
    Eigen::Index imax = 0;  // deterministic sign: largest translation positive
    md.w.cwiseAbs().maxCoeff(&imax);
    if (md.w(imax) < 0) md.w = -md.w;
    if (bending) md.th = -G * md.w;
    out.push_back(std::move(md));
  }
}

}  // namespace

FlexibleData beam_modal_data(const BeamSpec& spec) {
  const int n = spec.elements;
  if (!(spec.length > 0) || !(spec.mass_per_length > 0) || n < 1 || spec.modes < 1 || !(spec.EI[0] > 0) ||
      !(spec.EI[1] > 0) || spec.axis < 0 || spec.axis > 2 || (spec.sign != 1 && spec.sign != -1))
    throw std::invalid_argument("invalid beam specification");
  const bool axial = spec.EA.has_value();
  const int available = (axial ? 3 : 2) * n;
  if (spec.modes > available)
    throw std::invalid_argument("asks for " + std::to_string(spec.modes) + " modes but " + std::to_string(n) +
                                " elements give only " + std::to_string(available) +
                                "; expected more elements or fewer modes");

  const double L = spec.length, h = L / n, mu = spec.mass_per_length;
  const Vec3 d = spec.sign * Vec3::Unit(spec.axis);
  const Vec3 n1 = Vec3::Unit((spec.axis + 1) % 3), n2 = Vec3::Unit((spec.axis + 2) % 3);
  const Vec3 t[2] = {n1.cross(d), n2.cross(d)};  // deflection whose slope is a rotation about n1, n2
  const Vec3 nrm[2] = {n1, n2};

  // node masses (node 0 included: it is part of the body's mass)
  VecX mass(n + 1);
  for (int k = 0; k <= n; ++k) mass(k) = (k == 0 || k == n) ? 0.5 * mu * h : mu * h;
  const VecX mfree = mass.tail(n);

  std::vector<BeamMode> all;
  solve_plane(true, spec.EI[0], h, n, mfree, 0, all);
  solve_plane(true, spec.EI[1], h, n, mfree, 1, all);
  if (axial) solve_plane(false, *spec.EA, h, n, mfree, 2, all);
  std::stable_sort(all.begin(), all.end(), [](const BeamMode& a, const BeamMode& b) { return a.lambda < b.lambda; });

  const int m = spec.modes;
  FlexibleData flex;
  flex.source = "beam";
  for (int k = 0; k <= n; ++k) {
    ModalNode node;
    node.id = k + 1;
    node.rho_B = (k * h) * d;
    node.mass = mass(k);
    flex.nodes.push_back(node);
  }
  flex.Phi = MatX::Zero(3 * (n + 1), m);
  flex.Psi = MatX::Zero(3 * (n + 1), m);
  flex.frequency_hz = VecX::Zero(m);
  constexpr double kTwoPi = 6.283185307179586476925;
  for (int j = 0; j < m; ++j) {
    const BeamMode& md = all[j];
    flex.frequency_hz(j) = std::sqrt(md.lambda) / kTwoPi;
    for (int k = 1; k <= n; ++k) {
      if (md.kind == 2) {
        flex.Phi.block<3, 1>(3 * k, j) = md.w(k - 1) * d;
      } else {
        flex.Phi.block<3, 1>(3 * k, j) = md.w(k - 1) * t[md.kind];
        flex.Psi.block<3, 1>(3 * k, j) = md.th(k - 1) * nrm[md.kind];
      }
    }
  }
  flex.damping_ratio = VecX::Zero(m);
  flex.K = VecX::Zero(m);
  flex.D = VecX::Zero(m);
  return flex;
}

}  // namespace kanegen
