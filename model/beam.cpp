// Euler–Bernoulli cantilever, lumped masses and rotary inertias (beam.hpp).
//
// Nodes k = 0..n at s_k = k h along the beam direction d (h = L/n); node 0 is
// clamped at the body origin. Each element's mass mu h, rotary inertias
// rhoI_p h and polar inertia rhoJ h are lumped half to each end, so the nodes
// carry exactly the beam's mass and inertia (node 0 rigidly). Degrees of
// freedom per free node: in each bending plane p (normal axis n_p,
// deflection along t_p = n_p x d) the deflection w_p and the slope
// th_p = w_p' (a rotation about n_p), with the Hermite-cubic element
// stiffness of EI_p; with GJ the twist phi about d (linear elements); with EA
// the axial displacement (linear elements). Where a plane has no rotary
// inertia its slopes carry no inertia and are condensed statically (exact for
// this mass model); torsion needs a polar inertia to have modes.
//
// Each problem K x = lambda M x (K sparse, M diagonal) is solved for its
// lowest modes through the symmetric operator M^1/2 K^-1 M^1/2 (lowest_modes),
// so the shapes come out mass-normalized: Sum_k m_k t_k.t_k + r_k.J_k r_k = 1;
// large problems by Lanczos iteration, in time and memory linear in the
// number of elements (2,000 elements: well under a second).
//
// Foreshortening (dynamics.md): mode i's deflection w_i(s) in its plane is the
// cubic Hermite interpolation of its nodal deflections and slopes, and node k
// gets Gamma_k^d_ij = -Integral_0^{s_k} w_i'(s).w_j'(s) ds along d, integrated
// exactly per element (3-point Gauss-Legendre: the integrand is a quartic).
#include "model/beam.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/SparseCholesky>
#include <Spectra/SymEigsSolver.h>
#include <functional>
#include <limits>

namespace kanegen {

namespace {

enum class Kind { bend0, bend1, torsion, axial };

struct BeamMode {
  double lambda;  // omega^2
  Kind kind;
  VecX x;         // n values (free nodes 1..n): deflection, twist or axial displacement
  VecX th;        // n bending slopes (bending modes only)
};

/// Problems up to this many degrees of freedom are solved densely (all
/// modes); larger ones by Lanczos (Spectra) for the lowest modes only, with
/// a sparse factorization of K: time and memory linear in the size.
constexpr int kDenseLimit = 300;

/// The lowest `wanted` eigenpairs of K x = lambda M x, K sparse symmetric
/// positive definite (the clamped beam), M diagonal >= 0 (a zero mass: a
/// degree of freedom without inertia, condensed statically). Solved as the
/// symmetric problem A v = nu v, A = M_D^1/2 (K^-1)_DD M_D^1/2 on the
/// degrees of freedom D with mass (nu = 1/lambda), so x_D = M_D^-1/2 v is
/// mass-normalized; the massless ones follow from x = lambda K^-1 M x.
/// Sign fixed: the largest |entry| of the first `sign_block` entries positive.
std::vector<std::pair<double, VecX>> lowest_modes(const Eigen::SparseMatrix<double>& K, const VecX& M, int wanted,
                                                  int sign_block) {
  const int n = static_cast<int>(K.rows());
  std::vector<int> D;
  for (int i = 0; i < n; ++i)
    if (M(i) > 0) D.push_back(i);
  const int nd = static_cast<int>(D.size());
  wanted = std::min(wanted, nd);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(K);
  if (ldlt.info() != Eigen::Success) throw std::runtime_error("the stiffness matrix is singular");
  VecX sqrtM(nd);
  for (int i = 0; i < nd; ++i) sqrtM(i) = std::sqrt(M(D[i]));
  auto apply = [&](const double* x, double* y) {  // y = A x
    VecX f = VecX::Zero(n);
    for (int i = 0; i < nd; ++i) f(D[i]) = sqrtM(i) * x[i];
    const VecX z = ldlt.solve(f);
    for (int i = 0; i < nd; ++i) y[i] = sqrtM(i) * z(D[i]);
  };
  std::vector<std::pair<double, VecX>> out;  // (nu, v)
  if (nd <= kDenseLimit) {
    MatX A(nd, nd);
    VecX e = VecX::Zero(nd);
    for (int j = 0; j < nd; ++j) {
      e(j) = 1.0;
      apply(e.data(), A.col(j).data());
      e(j) = 0.0;
    }
    A = 0.5 * (A + A.transpose());
    Eigen::SelfAdjointEigenSolver<MatX> es(A);
    if (es.info() != Eigen::Success) throw std::runtime_error("eigenvalue problem failed");
    for (int j = nd - 1; j >= nd - wanted; --j) out.emplace_back(es.eigenvalues()(j), es.eigenvectors().col(j));
  } else {
    struct Op {
      using Scalar = double;
      int size;
      std::function<void(const double*, double*)> f;
      Eigen::Index rows() const { return size; }
      Eigen::Index cols() const { return size; }
      void perform_op(const double* x, double* y) const { f(x, y); }
    } op{nd, apply};
    Spectra::SymEigsSolver<Op> eigs(op, wanted, std::min(nd, 2 * wanted + 20));
    eigs.init();
    eigs.compute(Spectra::SortRule::LargestAlge, 1000, 1e-12);
    if (eigs.info() != Spectra::CompInfo::Successful) throw std::runtime_error("the Lanczos iteration did not converge");
    const VecX nu = eigs.eigenvalues();
    const MatX V = eigs.eigenvectors();
    for (int j = 0; j < wanted; ++j) out.emplace_back(nu(j), V.col(j));
  }
  std::vector<std::pair<double, VecX>> modes;
  for (auto& [nu, v] : out) {
    const double lambda = nu > 0 ? 1.0 / nu : std::numeric_limits<double>::infinity();
    VecX Mx = VecX::Zero(n);
    for (int i = 0; i < nd; ++i) Mx(D[i]) = sqrtM(i) * v(i);  // M x with x_D = v / sqrt(M_D)
    VecX x = lambda * ldlt.solve(Mx);
    for (int i = 0; i < nd; ++i) x(D[i]) = v(i) / sqrtM(i);  // exact on D
    Eigen::Index imax = 0;
    x.head(sign_block).cwiseAbs().maxCoeff(&imax);
    if (x(imax) < 0) x = -x;
    modes.emplace_back(lambda, std::move(x));
  }
  return modes;
}

/// Bending in one plane: stiffness EI, node masses m and slope inertias Jr
/// (free nodes 1..n; Jr zero: slopes condensed). Degrees of freedom
/// w_1..w_n, th_1..th_n.
void solve_bending(double EI, double h, int n, const VecX& m, const VecX& Jr, Kind kind, int wanted,
                   std::vector<BeamMode>& out) {
  std::vector<Eigen::Triplet<double>> t;
  const double c = EI / (h * h * h);
  const double ke[4][4] = {{12, 6 * h, -12, 6 * h},
                           {6 * h, 4 * h * h, -6 * h, 2 * h * h},
                           {-12, -6 * h, 12, -6 * h},
                           {6 * h, 2 * h * h, -6 * h, 4 * h * h}};
  for (int e = 0; e < n; ++e) {
    // element from node e to e + 1, dofs (w_e, th_e, w_e+1, th_e+1); node 0 clamped.
    const int node[4] = {e, e, e + 1, e + 1};
    const bool rot[4] = {false, true, false, true};
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) {
        if (node[a] == 0 || node[b] == 0) continue;
        t.emplace_back((rot[a] ? n : 0) + node[a] - 1, (rot[b] ? n : 0) + node[b] - 1, c * ke[a][b]);
      }
  }
  Eigen::SparseMatrix<double> K(2 * n, 2 * n);
  K.setFromTriplets(t.begin(), t.end());
  VecX M(2 * n);
  M << m, Jr;
  for (auto& [lambda, x] : lowest_modes(K, M, wanted, n)) out.push_back({lambda, kind, x.head(n), x.tail(n)});
}

/// Torsion or axial: linear elements of stiffness k / h, inertias M (free nodes).
void solve_linear(double stiffness, double h, int n, const VecX& M, Kind kind, int wanted, std::vector<BeamMode>& out) {
  std::vector<Eigen::Triplet<double>> t;
  const double c = stiffness / h;
  for (int e = 0; e < n; ++e) {  // element e .. e+1; free node k has index k - 1
    t.emplace_back(e, e, c);
    if (e > 0) {
      t.emplace_back(e - 1, e - 1, c);
      t.emplace_back(e - 1, e, -c);
      t.emplace_back(e, e - 1, -c);
    }
  }
  Eigen::SparseMatrix<double> K(n, n);
  K.setFromTriplets(t.begin(), t.end());
  for (auto& [lambda, x] : lowest_modes(K, M, wanted, n)) out.push_back({lambda, kind, x, VecX()});
}

/// Integral over one element of w_i'(s) w_j'(s) ds for Hermite cubics given
/// by end values (wa, ta, wb, tb) of each.
double element_slope_product(double h, const double (&di)[4], const double (&dj)[4]) {
  // dw/ds = (1/h) [N1' wa + h N2' ta + N3' wb + h N4' tb] (' = d/dxi)
  static const double xg[3] = {0.5 - 0.5 * std::sqrt(0.6), 0.5, 0.5 + 0.5 * std::sqrt(0.6)};
  static const double wg[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
  double sum = 0.0;
  for (int g = 0; g < 3; ++g) {
    const double x = xg[g];
    const double dN[4] = {-6 * x + 6 * x * x, h * (1 - 4 * x + 3 * x * x), 6 * x - 6 * x * x, h * (-2 * x + 3 * x * x)};
    double a = 0, b = 0;
    for (int k = 0; k < 4; ++k) a += dN[k] * di[k], b += dN[k] * dj[k];
    sum += wg[g] * a * b;
  }
  return sum / h;  // (1/h)^2 from the derivatives, h from ds = h dxi
}

}  // namespace

FlexibleData beam_modal_data(const BeamSpec& spec) {
  const int n = spec.elements;
  if (!(spec.length > 0) || !(spec.mass_per_length > 0) || n < 1 || spec.modes < 1 || !(spec.EI[0] > 0) ||
      !(spec.EI[1] > 0) || spec.axis < 0 || spec.axis > 2 || (spec.sign != 1 && spec.sign != -1) ||
      !(spec.rotary_inertia[0] >= 0) || !(spec.rotary_inertia[1] >= 0))
    throw std::invalid_argument("invalid beam specification");
  const double polar = spec.polar_inertia.value_or(spec.rotary_inertia[0] + spec.rotary_inertia[1]);
  const bool torsion = spec.GJ.has_value() && polar > 0;
  const bool axial = spec.EA.has_value();
  const int slopes = (spec.rotary_inertia[0] > 0 ? n : 0) + (spec.rotary_inertia[1] > 0 ? n : 0);
  const int available = 2 * n + slopes + (torsion ? n : 0) + (axial ? n : 0);
  if (spec.modes > available)
    throw std::invalid_argument("asks for " + std::to_string(spec.modes) + " modes but " + std::to_string(n) +
                                " elements give only " + std::to_string(available) +
                                "; expected more elements or fewer modes");

  const double L = spec.length, h = L / n, mu = spec.mass_per_length;
  const Vec3 d = spec.sign * Vec3::Unit(spec.axis);
  const Vec3 nrm[2] = {Vec3::Unit((spec.axis + 1) % 3), Vec3::Unit((spec.axis + 2) % 3)};
  const Vec3 t[2] = {nrm[0].cross(d), nrm[1].cross(d)};  // deflection whose slope is a rotation about n_p

  // Lumped node data (node 0 included: it is part of the body's mass).
  VecX w(n + 1);  // share of an element
  for (int k = 0; k <= n; ++k) w(k) = (k == 0 || k == n) ? 0.5 : 1.0;
  const VecX mass = mu * h * w;
  std::vector<BeamMode> all;
  // Each family contributes at most the `modes` lowest of its own; the lowest overall are kept.
  for (int p = 0; p < 2; ++p)
    solve_bending(spec.EI[p], h, n, mass.tail(n), spec.rotary_inertia[p] * h * w.tail(n),
                  p == 0 ? Kind::bend0 : Kind::bend1, spec.modes, all);
  if (torsion) solve_linear(*spec.GJ, h, n, polar * h * w.tail(n), Kind::torsion, spec.modes, all);
  if (axial) solve_linear(*spec.EA, h, n, mass.tail(n), Kind::axial, spec.modes, all);
  std::stable_sort(all.begin(), all.end(), [](const BeamMode& a, const BeamMode& b) { return a.lambda < b.lambda; });
  all.resize(spec.modes);

  const int m = spec.modes;
  FlexibleData flex;
  flex.source = "beam";
  for (int k = 0; k <= n; ++k) {
    ModalNode node;
    node.id = k + 1;
    node.rho_B = (k * h) * d;
    node.mass = mass(k);
    node.J_B = h * w(k) *
               (spec.rotary_inertia[0] * nrm[0] * nrm[0].transpose() + spec.rotary_inertia[1] * nrm[1] * nrm[1].transpose() +
                polar * d * d.transpose());
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
      switch (md.kind) {
        case Kind::bend0:
        case Kind::bend1: {
          const int p = md.kind == Kind::bend0 ? 0 : 1;
          flex.Phi.block<3, 1>(3 * k, j) = md.x(k - 1) * t[p];
          flex.Psi.block<3, 1>(3 * k, j) = md.th(k - 1) * nrm[p];
          break;
        }
        case Kind::torsion: flex.Psi.block<3, 1>(3 * k, j) = md.x(k - 1) * d; break;
        case Kind::axial: flex.Phi.block<3, 1>(3 * k, j) = md.x(k - 1) * d; break;
      }
    }
  }

  // Foreshortening: Gamma_k^d = -Integral_0^{s_k} w_i'.w_j' ds, along d.
  flex.Gamma.assign(n + 1, {});
  MatX acc = MatX::Zero(m, m);  // integral up to the current node
  auto ends = [&](const BeamMode& md, int e, double (&v)[4]) {  // (w, th) at nodes e, e + 1
    v[0] = e == 0 ? 0.0 : md.x(e - 1);
    v[1] = e == 0 ? 0.0 : md.th(e - 1);
    v[2] = md.x(e);
    v[3] = md.th(e);
  };
  for (int e = 0; spec.second_order && e < n; ++e) {
    for (int i = 0; i < m; ++i) {
      if (all[i].kind != Kind::bend0 && all[i].kind != Kind::bend1) continue;
      for (int j = i; j < m; ++j) {
        if (all[j].kind != all[i].kind) continue;  // w_i' . w_j' = 0 across planes
        double di[4], dj[4];
        ends(all[i], e, di);
        ends(all[j], e, dj);
        acc(i, j) += element_slope_product(h, di, dj);
        acc(j, i) = acc(i, j);
      }
    }
    if (!acc.isZero(0.0)) flex.Gamma[e + 1][spec.axis] = -spec.sign * acc;
  }
  flex.damping_ratio = VecX::Zero(m);
  flex.K = VecX::Zero(m);
  flex.D = VecX::Zero(m);
  return flex;
}

}  // namespace kanegen
