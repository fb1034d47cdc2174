// The generic numeric path: Kane's method evaluated directly from the Model at
// run time (kinematics.hpp -> body_terms.hpp -> mass_matrix.hpp / forcing.hpp
// -> Cholesky solve; reactions.hpp; energy_momentum.hpp), with a workspace
// allocated once. It uses no generated code and cross-checks it.
#pragma once

#include <Eigen/Cholesky>

#include "engine.hpp"
#include "workspace.hpp"

namespace kanegen {

class GenericEngine final : public Engine {
 public:
  explicit GenericEngine(const Model& model);
  std::string name() const override { return "generic"; }

  void qdot(const VecX& q, const VecX& u, VecX& qdot) override;
  void mass_matrix(const VecX& q, MatX& M) override;
  void forcing(const VecX& q, const VecX& u, const VecX& tau, VecX& F) override;
  void udot(const VecX& q, const VecX& u, const VecX& tau, VecX& udot) override;
  EnergyValues energy(const VecX& q, const VecX& u) override;
  MomentumValues momentum(const VecX& q, const VecX& u) override;
  void reactions(const VecX& q, const VecX& u, const VecX& udot, std::vector<Reaction>& out) override;

  const Workspace<double>& workspace() const { return ws_; }

 private:
  void update(const VecX& q, const VecX& u);
  Workspace<double> ws_;
  Eigen::LLT<MatX> llt_;
  VecX zero_u_;
};

/// Throws SingularMassMatrix (with the rcond) unless M is positive definite
/// and reasonably conditioned; `llt` is then the factorization of M.
void factorize_mass_matrix(const MatX& M, Eigen::LLT<MatX>& llt);

}  // namespace kanegen
