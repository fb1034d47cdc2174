#include "generic_engine.hpp"

#include <fmt/format.h>

#include "body_terms.hpp"
#include "energy_momentum.hpp"
#include "forcing.hpp"
#include "kinematic_equations.hpp"
#include "kinematics.hpp"
#include "mass_matrix.hpp"
#include "reactions.hpp"

namespace kanegen {

GenericEngine::GenericEngine(const Model& model) : Engine(model), ws_(model), llt_(model.nu) {}

void GenericEngine::update(const VecX& q, const VecX& u) {
  compute_kinematics(model(), ws_, q, u);
  compute_body_terms(model(), ws_);
}

void GenericEngine::qdot(const VecX& q, const VecX& u, VecX& qdot) {
  qdot.resize(model().nq);
  compute_qdot<double>(model(), q, u, qdot);
}

void GenericEngine::mass_matrix(const VecX& q, MatX& M) {
  zero_u_.setZero(model().nu);  // M does not depend on u; allocated once
  update(q, zero_u_);
  compute_mass_matrix(model(), ws_);
  M = ws_.M;
}

void GenericEngine::forcing(const VecX& q, const VecX& u, const VecX& tau, VecX& F) {
  update(q, u);
  compute_forcing(model(), ws_, q, u, tau);
  F = ws_.F;
}

void factorize_mass_matrix(const MatX& M, Eigen::LLT<MatX>& llt) {
  llt.compute(M);
  // cond(M) >= (max L_ii / min L_ii)^2: a ratio below 1e-14 leaves u-dot no
  // correct digit. (Cheap and allocation-free, unlike Eigen's rcond estimate.)
  double ratio = 0.0;
  if (llt.info() == Eigen::Success && M.rows() > 0) {
    const auto d = llt.matrixLLT().diagonal();
    const double lo = d.minCoeff(), hi = d.maxCoeff();
    ratio = hi > 0 ? (lo / hi) * (lo / hi) : 0.0;
  } else if (M.rows() == 0) {
    ratio = 1.0;
  }
  if (!(ratio > 1e-14))
    throw SingularMassMatrix(
        fmt::format("mass matrix is singular (Cholesky pivot ratio squared {:.3g}, i.e. cond(M) above 1e14)", ratio));
}

void GenericEngine::udot(const VecX& q, const VecX& u, const VecX& tau, VecX& udot) {
  update(q, u);
  compute_mass_matrix(model(), ws_);
  compute_forcing(model(), ws_, q, u, tau);
  factorize_mass_matrix(ws_.M, llt_);
  udot = llt_.solve(ws_.F);
}

EnergyValues GenericEngine::energy(const VecX& q, const VecX& u) {
  update(q, u);
  const auto E = compute_energy(model(), ws_, q);
  return {E.T, E.V};
}

MomentumValues GenericEngine::momentum(const VecX& q, const VecX& u) {
  update(q, u);
  const auto P = compute_momentum(model(), ws_);
  return {P.p_N, P.H_N};
}

void GenericEngine::reactions(const VecX& q, const VecX& u, const VecX& udot, std::vector<Reaction>& out) {
  update(q, u);
  compute_reactions(model(), ws_, udot);
  out.resize(model().bodies.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i].force_B = ws_.body[i].wrench_B.head<3>();
    out[i].torque_B = ws_.body[i].wrench_B.tail<3>();
  }
}

}  // namespace kanegen
