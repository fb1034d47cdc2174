// The Engine over generated code: a KanegenGeneratedApi table
// (generated_api.h) obtained from a JIT-compiled shared library (jit.hpp) or
// linked in directly (ahead-of-time simulators, kanegen_add_model()). Its
// functions are found by name; qdot, mass_matrix, forcing and udot are
// required, the others optional. The table is checked against the Model on
// construction: API version, nq/nu/nbodies and the model hash (model_hash.hpp)
// must agree, and the generator hash too when one is expected.
#pragma once

#include <memory>

#include "engine/engine.hpp"
#include "engine/generated_api.h"

namespace kanegen {

/// The function of `api`'s table called `name`, or null.
KanegenFunctionPtr find_function(const KanegenGeneratedApi& api, const std::string& name);

class GeneratedEngine final : public Engine {
 public:
  /// `library` keeps the shared object holding `api` loaded (may be null when
  /// the code is linked in). Throws std::runtime_error on any mismatch
  /// between the table and the model (or `expected_generator_hash`, if not empty).
  /// `implicit`: parameters the code takes after the model's own
  /// (implicit_parameters(), model/parameters.hpp), fed with the model's
  /// values: the code was generated from the model with them appended.
  GeneratedEngine(const Model& model, const KanegenGeneratedApi* api, std::shared_ptr<void> library = nullptr,
                  const std::string& expected_generator_hash = {}, std::vector<RuntimeParameter> implicit = {});
  std::string name() const override { return "generated"; }

  bool has_jacobian() const override { return jacobian_ != nullptr; }
  bool jacobian_for_integration() const override { return has_jacobian() && jacobian_for_integration_; }
  /// false: the compiled Jacobian is slower than differencing u-dot (a large model's, built at -O0 for linearize).
  void set_jacobian_for_integration(bool on) { jacobian_for_integration_ = on; }
  const KanegenGeneratedApi& api() const { return *api_; }
  /// The function of the table called `name`, or null.
  KanegenFunctionPtr function(const std::string& name) const;
  /// Path of the shared library the code came from, empty when linked in.
  const std::string& library_path() const { return library_path_; }
  void set_library_path(std::string path) { library_path_ = std::move(path); }
  /// The u-dot form of the code ("composite" or "articulated"; empty when not known, e.g. linked in).
  const std::string& udot_form() const { return udot_form_; }
  void set_udot_form(std::string form) { udot_form_ = std::move(form); }

  /// u-dot (and state_derivative) from `fn` instead: the same function built otherwise, in `library` (kept
  /// loaded), e.g. by a second compiler (jit.cpp). `compiler` names it for reports.
  void use_udot(KanegenFunctionPtr fn, std::shared_ptr<void> library, std::string compiler);
  /// The compiler of the u-dot in use when use_udot() replaced it; empty: the library's own.
  const std::string& udot_compiler() const { return udot_compiler_; }
  KanegenFunctionPtr udot_function() const { return udot_; }
  /// Calls `fn` (a u-dot of this model's table, or of another build of it) at (t, q, u, tau) with this
  /// engine's inputs and parameters, writing nu doubles to `out`; returns its status.
  int call_udot(KanegenFunctionPtr fn, double t, const VecX& q, const VecX& u, const VecX& tau, double* out) const;

  /// x_dot = [q_dot; u_dot] straight from x = [q; u] (nq + nu doubles, tau nu
  /// doubles): no copies, no size checks, for an integrator's right-hand
  /// side. Returns 0, or the 1-based speed of a non-positive pivot (udot()
  /// then throws the SingularMassMatrix that names it).
  int state_derivative(double t, const double* x, const double* tau, double* xdot) const {
    const int nq = model().nq;
    const KanegenArgs a{t, x, x + nq, tau, nullptr, inputs().data(), code_parameters_.data()};
    qdot_(&a, xdot);
    return udot_(&a, xdot + nq);
  }

 protected:
  void do_qdot(const VecX& q, const VecX& u, VecX& qdot) override;
  void do_mass_matrix(double t, const VecX& q, MatX& M) override;
  void do_forcing(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& F) override;
  /// Throws SingularMassMatrix when the generated factorization meets a non-positive pivot.
  void do_udot(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& udot) override;
  /// These throw std::runtime_error when the model's `outputs:` did not ask for them.
  EnergyValues do_energy(double t, const VecX& q, const VecX& u) override;
  MomentumValues do_momentum(double t, const VecX& q, const VecX& u) override;
  void do_reactions(double t, const VecX& q, const VecX& u, const VecX& udot, std::vector<Reaction>& out) override;
  /// Returns false when the code has no Jacobian (left out of a very large model).
  bool do_jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& J) override;
  void do_outputs(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& y) override;
  bool do_input_jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& B) override;
  bool do_output_jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& CD) override;
  void parameters_changed() override;

 private:
  [[noreturn]] void missing_output(const char* what) const;
  [[noreturn]] void singular(int pivot) const;
  const KanegenGeneratedApi* api_;
  std::shared_ptr<void> library_;
  std::string library_path_;
  std::string udot_form_;
  std::shared_ptr<void> udot_library_;
  std::string udot_compiler_;
  KanegenFunctionPtr qdot_ = nullptr, mass_matrix_ = nullptr, forcing_ = nullptr, udot_ = nullptr,
                     jacobian_ = nullptr, energy_ = nullptr, momentum_ = nullptr, reactions_ = nullptr,
                     outputs_ = nullptr, input_jacobian_ = nullptr, output_jacobian_ = nullptr;
  std::vector<double> wrenches_;
  MatX M_row_major_;
  /// What the code's prm[] gets: the model's parameters, then the implicit ones.
  VecX code_parameters_;
  bool jacobian_for_integration_ = true;
};

}  // namespace kanegen
