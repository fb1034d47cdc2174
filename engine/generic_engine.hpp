// The generic numeric path: Kane's method evaluated directly from the Model at
// run time (dynamics/: kinematics -> body_terms -> mass_matrix / forcing ->
// Cholesky solve; reactions; invariants), with a workspace allocated once. It
// uses no generated code and cross-checks it.
#pragma once

#include <Eigen/Cholesky>

#include "dynamics/workspace.hpp"
#include "engine/engine.hpp"

namespace kanegen {

class GenericEngine final : public Engine {
 public:
  explicit GenericEngine(const Model& model);
  std::string name() const override { return "generic"; }
  const Workspace<double>& workspace() const { return ws_; }

 protected:
  void do_qdot(const VecX& q, const VecX& u, VecX& qdot) override;
  void do_mass_matrix(double t, const VecX& q, MatX& M) override;
  void do_forcing(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& F) override;
  void do_udot(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& udot) override;
  EnergyValues do_energy(double t, const VecX& q, const VecX& u) override;
  MomentumValues do_momentum(double t, const VecX& q, const VecX& u) override;
  void do_reactions(double t, const VecX& q, const VecX& u, const VecX& udot, std::vector<Reaction>& out) override;
  void do_outputs(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& y) override;
  void do_set_parameters(const Model& with_values) override;

 private:
  void update(double t, const VecX& q, const VecX& u);
  /// The model with the current runtime parameter values written in: what every evaluation reads.
  const Model& m() const { return with_parameters_; }
  Model with_parameters_;
  Workspace<double> ws_;
  Eigen::LLT<MatX> llt_;
  VecX zero_u_;
};

/// Throws SingularMassMatrix (with the pivot ratio) unless M is positive
/// definite and reasonably conditioned; `llt` is then the factorization of M.
void factorize_mass_matrix(const MatX& M, Eigen::LLT<MatX>& llt);

}  // namespace kanegen
