// The runtime's view of a model's equations of motion, whichever way they are
// computed: GenericEngine (reads the Model at run time) or the adapter around
// generated code. Everything else (CLI, simulation, cross-checks) depends only
// on this interface. All quantities follow dynamics.md; q holds unit
// quaternions (the engines normalize what they use).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "model.hpp"

namespace kanegen {

struct Reaction {
  Vec3 force_B = Vec3::Zero();   ///< on the body from its parent, body components
  Vec3 torque_B = Vec3::Zero();  ///< about the body's joint point O_B, body components
};

struct EnergyValues {
  double T = 0, V = 0;
};
struct MomentumValues {
  Vec3 p_N = Vec3::Zero(), H_N = Vec3::Zero();
};

/// M(q) is not positive definite at the state (e.g. a massless chain).
class SingularMassMatrix : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Engine {
 public:
  explicit Engine(const Model& model) : model_(model) {}
  virtual ~Engine() = default;
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  const Model& model() const { return model_; }
  virtual std::string name() const = 0;

  virtual void qdot(const VecX& q, const VecX& u, VecX& qdot) = 0;
  virtual void mass_matrix(const VecX& q, MatX& M) = 0;
  virtual void forcing(const VecX& q, const VecX& u, const VecX& tau, VecX& F) = 0;
  /// Solves M u_dot = F; throws SingularMassMatrix.
  virtual void udot(const VecX& q, const VecX& u, const VecX& tau, VecX& udot) = 0;
  virtual EnergyValues energy(const VecX& q, const VecX& u) = 0;
  virtual MomentumValues momentum(const VecX& q, const VecX& u) = 0;
  /// Reactions on every body given the accelerations u_dot (from udot()).
  virtual void reactions(const VecX& q, const VecX& u, const VecX& udot, std::vector<Reaction>& out) = 0;
  /// Exact Jacobian of x_dot = [q_dot; u_dot] w.r.t. x = [q; u] (column-major
  /// into J, (nq+nu)^2), if this engine provides one; false otherwise (the
  /// implicit integrators then use finite differences).
  virtual bool jacobian(const VecX& q, const VecX& u, const VecX& tau, MatX& J) {
    (void)q, (void)u, (void)tau, (void)J;
    return false;
  }

 private:
  const Model& model_;
};

}  // namespace kanegen
