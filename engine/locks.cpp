#include "engine/locks.hpp"

#include <fmt/format.h>

#include "engine/engine.hpp"

namespace kanegen {

namespace {

/// The speeds not in `locked` (ascending), of nu.
std::vector<int> free_speeds(int nu, const std::vector<int>& locked) {
  std::vector<int> f;
  std::size_t k = 0;
  for (int i = 0; i < nu; ++i) {
    if (k < locked.size() && locked[k] == i) {
      ++k;
      continue;
    }
    f.push_back(i);
  }
  return f;
}

MatX rows_cols(const MatX& M, const std::vector<int>& r, const std::vector<int>& c) {
  MatX out(static_cast<Eigen::Index>(r.size()), static_cast<Eigen::Index>(c.size()));
  for (std::size_t i = 0; i < r.size(); ++i)
    for (std::size_t j = 0; j < c.size(); ++j) out(i, j) = M(r[i], c[j]);
  return out;
}

/// Solves M_ff x = b by Cholesky; throws SingularMassMatrix naming the first free speed whose pivot failed.
VecX solve_free(const MatX& M_ff, const VecX& b, const std::vector<int>& f) {
  Eigen::LLT<MatX> llt(M_ff);
  if (llt.info() != Eigen::Success || !llt.matrixLLT().diagonal().allFinite()) {
    throw SingularMassMatrix(
        fmt::format("the mass matrix of the free speeds (with {} speeds locked) is not positive definite",
                    M_ff.rows() == 0 ? 0 : static_cast<long>(f.size())),
        f.empty() ? -1 : f[0]);
  }
  return llt.solve(b);
}

}  // namespace

void reduced_udot(const MatX& M, const VecX& F, const std::vector<int>& locked, VecX& udot) {
  const int nu = static_cast<int>(M.rows());
  const std::vector<int> f = free_speeds(nu, locked);
  udot.setZero(nu);
  if (f.empty()) return;
  VecX F_f(static_cast<Eigen::Index>(f.size()));
  for (std::size_t i = 0; i < f.size(); ++i) F_f(i) = F(f[i]);
  const VecX ud_f = solve_free(rows_cols(M, f, f), F_f, f);
  for (std::size_t i = 0; i < f.size(); ++i) udot(f[i]) = ud_f(i);
}

LatchImpact latch_impact(const MatX& M, const VecX& u_minus, const std::vector<int>& locked_after) {
  const int nu = static_cast<int>(M.rows());
  const std::vector<int> f = free_speeds(nu, locked_after);
  LatchImpact r;
  r.u_plus = u_minus;
  // Only the speeds being stopped enter (no cancellation of the large T of an orbit, docs/decisions.md): the
  // free speeds' momentum M_ff u_f+ = M_ff u_f- + M_fl u_l- gives the jump du_f = M_ff^-1 M_fl u_l-, and
  // T- - T+ = 1/2 u_l-' (M_ll - M_lf M_ff^-1 M_fl) u_l- (the Schur complement: >= 0).
  VecX u_l(static_cast<Eigen::Index>(locked_after.size()));
  for (std::size_t i = 0; i < locked_after.size(); ++i) u_l(i) = u_minus(locked_after[i]);
  const MatX M_ll = rows_cols(M, locked_after, locked_after);
  double lost = u_l.dot(M_ll * u_l);
  if (!f.empty()) {
    const VecX c = rows_cols(M, f, locked_after) * u_l;
    const VecX du_f = solve_free(rows_cols(M, f, f), c, f);
    for (std::size_t i = 0; i < f.size(); ++i) r.u_plus(f[i]) += du_f(i);
    lost -= c.dot(du_f);
  }
  for (const int k : locked_after) r.u_plus(k) = 0.0;
  r.energy_lost = 0.5 * lost;
  return r;
}

}  // namespace kanegen
