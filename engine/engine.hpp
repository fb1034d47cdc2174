// The runtime's view of a model's equations of motion, whichever way they are
// computed: GenericEngine (reads the Model at run time, dynamics/) or
// GeneratedEngine (the model's generated code, through the C table of
// generated_api.h). Everything else (CLI, simulation, cross-checks) depends
// only on this interface. All quantities follow dynamics.md; q holds unit
// quaternions (the engines normalize what they use). `t` matters only for
// models with prescribed motion; the overloads without it evaluate at t = 0.
//
// Public methods are non-virtual: they check sizes once and call the
// protected do_* implementations (so that overloads are not hidden in
// derived classes).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/model.hpp"

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
/// `speed` is the index of a speed whose pivot failed (-1 if unknown).
class SingularMassMatrix : public std::runtime_error {
 public:
  explicit SingularMassMatrix(const std::string& what, int speed = -1) : std::runtime_error(what), speed(speed) {}
  int speed;
};

class Engine {
 public:
  explicit Engine(const Model& model) : model_(model), w_(VecX::Zero(model.nw)), p_(nominal_parameters(model)) {}
  virtual ~Engine() = default;
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  const Model& model() const { return model_; }
  virtual std::string name() const = 0;

  void qdot(const VecX& q, const VecX& u, VecX& qdot);
  void mass_matrix(double t, const VecX& q, MatX& M);
  void forcing(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& F);
  /// Solves M u_dot = F; throws SingularMassMatrix.
  /// With joints locked (set_locks), the reduced system's: M_ff u_dot_f = F_f, u_dot_l = 0.
  void udot(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& udot);
  EnergyValues energy(double t, const VecX& q, const VecX& u);
  MomentumValues momentum(double t, const VecX& q, const VecX& u);
  /// Reactions on every body given the accelerations u_dot (from udot()).
  void reactions(double t, const VecX& q, const VecX& u, const VecX& udot, std::vector<Reaction>& out);
  /// Exact Jacobian of x_dot = [q_dot; u_dot] w.r.t. x = [q; u] ((nq+nu)^2),
  /// if this engine provides one; false otherwise (the implicit integrators
  /// then use finite differences). Throws SingularMassMatrix.
  /// false while joints are locked (the exact Jacobian is the free system's).
  bool jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& J);
  /// Whether jacobian() gives exact Jacobians.
  virtual bool has_jacobian() const { return false; }
  /// The implicit integrators use jacobian() (else they difference the right-hand side).
  virtual bool jacobian_for_integration() const { return has_jacobian(); }

  /// The named inputs w (model().nw values, docs/gnc.md) that forcing, udot,
  /// reactions, the Jacobians and outputs use from now on; zero until set
  /// (as MuJoCo's mjData.ctrl). Throws std::invalid_argument on a wrong size.
  void set_inputs(const VecX& w);
  /// The joints locked from now on (per body, model/events.hpp; dynamics.md
  /// "Locks"): udot() and outputs() give the reduced system's accelerations,
  /// the reactions at a locked joint include the locking wrench (pass the
  /// reduced u_dot). Empty or all free: none locked. Throws
  /// std::invalid_argument for a wrong size or a joint that cannot lock.
  void set_locks(const LockSet& locks);
  const LockSet& locks() const { return locks_; }
  bool has_locks() const { return !locked_u_.empty(); }
  /// The speeds the locks hold at zero (ascending).
  const std::vector<int>& locked_u() const { return locked_u_; }
  /// tau plus the locking torque on the locked speeds, the one that holds them still: the free system's
  /// u_dot at u_l = 0 with it applied is the reduced system's (dynamics.md, Locks). tau when none is locked.
  VecX locked_tau(double t, const VecX& q, const VecX& u, const VecX& tau);
  const VecX& inputs() const { return w_; }
  /// Values of the model's runtime parameters (model().parameters, in order;
  /// docs/sweeps.md), used by every evaluation from now on; the nominal values
  /// until set. Throws std::invalid_argument on a wrong size or a value out of
  /// its domain (a negative mass, ...); the values are unchanged then.
  void set_parameters(const VecX& p);
  const VecX& parameters() const { return p_; }
  static VecX nominal_parameters(const Model& model);
  /// The named outputs y (model().ny values) at the state, with the current
  /// inputs and tau (accelerations and reactions depend on them); with joints
  /// locked, the reduced system's (set_locks).
  void outputs(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& y);
  /// Exact d(u_dot)/dw (nu x nw), if this engine provides it. Throws SingularMassMatrix.
  bool input_jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& B);
  /// Exact dy/d[q; u; w; tau] (ny x (nq + 2 nu + nw)), if this engine provides it.
  bool output_jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& CD);

  void mass_matrix(const VecX& q, MatX& M) { mass_matrix(0.0, q, M); }
  void forcing(const VecX& q, const VecX& u, const VecX& tau, VecX& F) { forcing(0.0, q, u, tau, F); }
  void udot(const VecX& q, const VecX& u, const VecX& tau, VecX& ud) { udot(0.0, q, u, tau, ud); }
  EnergyValues energy(const VecX& q, const VecX& u) { return energy(0.0, q, u); }
  MomentumValues momentum(const VecX& q, const VecX& u) { return momentum(0.0, q, u); }
  void reactions(const VecX& q, const VecX& u, const VecX& ud, std::vector<Reaction>& out) {
    reactions(0.0, q, u, ud, out);
  }
  bool jacobian(const VecX& q, const VecX& u, const VecX& tau, MatX& J) { return jacobian(0.0, q, u, tau, J); }

 protected:
  virtual void do_qdot(const VecX& q, const VecX& u, VecX& qdot) = 0;
  virtual void do_mass_matrix(double t, const VecX& q, MatX& M) = 0;
  virtual void do_forcing(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& F) = 0;
  virtual void do_udot(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& udot) = 0;
  virtual EnergyValues do_energy(double t, const VecX& q, const VecX& u) = 0;
  virtual MomentumValues do_momentum(double t, const VecX& q, const VecX& u) = 0;
  virtual void do_reactions(double t, const VecX& q, const VecX& u, const VecX& udot, std::vector<Reaction>& out) = 0;
  virtual bool do_jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& J) {
    (void)t, (void)q, (void)u, (void)tau, (void)J;
    return false;
  }
  virtual void do_outputs(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& y) = 0;
  /// Called by set_parameters() with the new values (validated by applying them to a copy of the model).
  virtual void do_set_parameters(const Model& with_values) { (void)with_values; }
  /// Called after parameters() took new values.
  virtual void parameters_changed() {}
  virtual bool do_input_jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& B) {
    (void)t, (void)q, (void)u, (void)tau, (void)B;
    return false;
  }
  virtual bool do_output_jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& CD) {
    (void)t, (void)q, (void)u, (void)tau, (void)CD;
    return false;
  }

 private:
  /// Throws std::invalid_argument unless q has nq entries and each of `nu_sized` nu.
  void check_sizes(const VecX& q, std::initializer_list<const VecX*> nu_sized) const;
  const Model& model_;
  VecX w_;
  VecX p_;
  LockSet locks_;
  std::vector<int> locked_u_;
  MatX M_lock_;  ///< workspace of the reduced u_dot
  VecX F_lock_, u_lock_, tau_lock_;
};

/// Sets an engine's locks for a scope (a run, an evaluation at a state) and
/// puts back the ones it had when the scope ends.
class ScopedLocks {
 public:
  ScopedLocks(Engine& engine, const LockSet& locks) : engine_(engine), before_(engine.locks()) {
    engine.set_locks(locks);
  }
  ~ScopedLocks() { engine_.set_locks(before_); }
  ScopedLocks(const ScopedLocks&) = delete;
  ScopedLocks& operator=(const ScopedLocks&) = delete;

 private:
  Engine& engine_;
  LockSet before_;
};

}  // namespace kanegen
