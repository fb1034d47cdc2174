#include "engine/generic_engine.hpp"

#include <fmt/format.h>

#include "dynamics/body_terms.hpp"
#include "dynamics/forcing.hpp"
#include "dynamics/invariants.hpp"
#include "dynamics/kinematic_equations.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/mass_matrix.hpp"
#include "dynamics/reactions.hpp"
#include "dynamics/sensors.hpp"

namespace kanegen {

GenericEngine::GenericEngine(const Model& model)
    : Engine(model), with_parameters_(model), ws_(model), llt_(model.nu), zero_u_(VecX::Zero(model.nu)) {}

void GenericEngine::do_set_parameters(const Model& with_values) { with_parameters_ = with_values; }

void GenericEngine::update(double t, const VecX& q, const VecX& u) {
  compute_kinematics(m(), ws_, t, q, u);
  compute_body_terms(m(), ws_);
}

void GenericEngine::do_qdot(const VecX& q, const VecX& u, VecX& qdot) { compute_qdot<double>(m(), q, u, qdot); }

void GenericEngine::do_mass_matrix(double t, const VecX& q, MatX& M) {
  update(t, q, zero_u_);  // M does not depend on u
  compute_mass_matrix(m(), ws_);
  M = ws_.M;
}

void GenericEngine::do_forcing(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& F) {
  update(t, q, u);
  compute_forcing(m(), ws_, q, u, tau, inputs());
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

void GenericEngine::do_udot(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& udot) {
  update(t, q, u);
  compute_mass_matrix(m(), ws_);
  compute_forcing(m(), ws_, q, u, tau, inputs());
  factorize_mass_matrix(ws_.M, llt_);
  udot = llt_.solve(ws_.F);
}

EnergyValues GenericEngine::do_energy(double t, const VecX& q, const VecX& u) {
  update(t, q, u);
  const auto E = compute_energy(m(), ws_, q);
  return {E.T, E.V};
}

MomentumValues GenericEngine::do_momentum(double t, const VecX& q, const VecX& u) {
  update(t, q, u);
  const auto P = compute_momentum(m(), ws_);
  return {P.p_N, P.H_N};
}

void GenericEngine::do_reactions(double t, const VecX& q, const VecX& u, const VecX& udot, std::vector<Reaction>& out) {
  update(t, q, u);
  compute_reactions(m(), ws_, udot, inputs());
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i].force_B = ws_.body[i].wrench_B.head<3>();
    out[i].torque_B = ws_.body[i].wrench_B.tail<3>();
  }
}

void GenericEngine::do_outputs(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& y) {
  update(t, q, u);
  compute_mass_matrix(m(), ws_);
  compute_forcing(m(), ws_, q, u, tau, inputs());
  factorize_mass_matrix(ws_.M, llt_);
  ws_.udot = llt_.solve(ws_.F);
  compute_reactions(m(), ws_, ws_.udot, inputs());
  compute_sensor_outputs(m(), ws_, y);
}

}  // namespace kanegen
