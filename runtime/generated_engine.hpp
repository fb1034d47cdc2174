// The Engine over generated code: a KanegenGeneratedApi table (generated_api.h)
// obtained from a JIT-compiled shared library (jit.hpp) or linked in directly
// (AOT simulators, cmake/KanegenAddModel.cmake). The table is checked against
// the Model on construction: API version, generator version, nq/nu/nbodies
// and the model hash (model_hash.hpp) must all agree.
#pragma once

#include <memory>

#include "engine.hpp"
#include "generated_api.h"

namespace kanegen {

class GeneratedEngine final : public Engine {
 public:
  /// `library` keeps the shared object holding `api` loaded (may be null when
  /// the code is linked in). Throws std::runtime_error on any mismatch
  /// between the table and the model.
  GeneratedEngine(const Model& model, const KanegenGeneratedApi* api, std::shared_ptr<void> library = nullptr);
  std::string name() const override { return "generated"; }

  void qdot(const VecX& q, const VecX& u, VecX& qdot) override;
  void mass_matrix(const VecX& q, MatX& M) override;
  void forcing(const VecX& q, const VecX& u, const VecX& tau, VecX& F) override;
  /// Throws SingularMassMatrix when the generated factorization meets a non-positive pivot.
  void udot(const VecX& q, const VecX& u, const VecX& tau, VecX& udot) override;
  /// These throw std::runtime_error when the model's `outputs:` did not ask for them.
  EnergyValues energy(const VecX& q, const VecX& u) override;
  MomentumValues momentum(const VecX& q, const VecX& u) override;
  void reactions(const VecX& q, const VecX& u, const VecX& udot, std::vector<Reaction>& out) override;

  /// Dense Jacobian of [q_dot; u_dot] w.r.t. [q; u], (nq+nu) x (nq+nu).
  /// Returns false (J unspecified) when M is singular at the state.
  bool jacobian(const VecX& q, const VecX& u, const VecX& tau, MatX& J) override;

  const KanegenGeneratedApi& api() const { return *api_; }
  /// Path of the shared library the code came from, empty when linked in.
  const std::string& library_path() const { return library_path_; }
  void set_library_path(std::string path) { library_path_ = std::move(path); }

 private:
  void check_sizes(const VecX& q, const VecX* u, const VecX* v) const;
  [[noreturn]] void missing_output(const char* what) const;
  const KanegenGeneratedApi* api_;
  std::shared_ptr<void> library_;
  std::string library_path_;
  std::vector<double> wrenches_;
};

}  // namespace kanegen
