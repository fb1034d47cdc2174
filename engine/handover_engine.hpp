// An engine that starts on the generic engine and hands over to the model's
// generated code once a background build of it is ready: a first run of a model
// starts integrating at once instead of waiting for the compiler
// (`kanegen simulate --engine auto` when no compiled library is cached).
//
// The build runs in a thread of its own (e.g. waiting for a background
// `kanegen compile`, then loading the cached library); every call of the
// engine checks one atomic flag and, once the library is loaded, forwards to
// it. The thread is detached: a run that ends first does not wait for it. The two engines evaluate the same equations (they
// agree to round-off, tests/engine/test_generated_engine.cpp), so a run crosses
// over within its tolerance; it is not bit-for-bit the run of either engine
// alone (docs/decisions.md). Energy and momentum always come from the generic
// engine (they are evaluated at output rows, and the generated code has them
// only when the model's outputs ask). It has no exact Jacobian (implicit methods use
// SUNDIALS' finite differences): a named implicit method waits for the build.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "engine/engine.hpp"

namespace kanegen {

class HandoverEngine final : public Engine {
 public:
  /// `build` makes the generated engine (called once, in the background thread,
  /// and kept alive with what it captures as long as the engine it returns);
  /// an exception from it keeps the generic engine for the whole run (error()
  /// says why).
  HandoverEngine(const Model& model, std::function<std::unique_ptr<Engine>()> build);

  /// "generic" before the handover, "generic, then generated from t = 1.25 s" after.
  std::string name() const override;
  /// The run's time span. With it, once the generic engine has run for a
  /// second of wall time, the engine projects the wall time it still needs;
  /// beyond `wait_beyond` seconds it waits for the build (which then has the
  /// machine) instead of racing it: a long run pays the compile once and runs
  /// the rest fast, a short one never waits.
  void set_horizon(double t0, double t_end, double wait_beyond = 30.0);
  /// Blocks until the build is done (tests; a command need not wait).
  void wait() const;
  bool build_done() const { return build_->ready.load(std::memory_order_acquire); }
  /// Why the build failed ("" while it runs or when it succeeded).
  std::string error() const;
  bool handed_over() const { return compiled_ != nullptr; }
  /// The simulated time of the first call on the generated engine (NaN before).
  double handover_time() const { return handover_t_; }

 protected:
  void do_qdot(const VecX& q, const VecX& u, VecX& qdot) override;
  void do_mass_matrix(double t, const VecX& q, MatX& M) override;
  void do_forcing(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& F) override;
  void do_udot(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& udot) override;
  EnergyValues do_energy(double t, const VecX& q, const VecX& u) override;
  MomentumValues do_momentum(double t, const VecX& q, const VecX& u) override;
  void do_reactions(double t, const VecX& q, const VecX& u, const VecX& udot, std::vector<Reaction>& out) override;
  void do_outputs(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& y) override;

 private:
  /// Waits for the build when the generic engine's projected remaining wall time exceeds wait_beyond_.
  void maybe_wait(double t);
  /// The engine to use now (adopting the built one when ready), with this
  /// engine's inputs and parameters.
  Engine& current(double t);
  /// `e` with this engine's inputs and parameters.
  Engine& synced(Engine& e);

  /// Shared with the (detached) build thread, which may outlive the engine.
  struct Build {
    std::function<std::unique_ptr<Engine>()> make;
    std::unique_ptr<Engine> engine;  ///< written by the thread before `ready`
    std::string error;               ///< likewise
    std::atomic<bool> ready{false};
    mutable std::mutex mutex;
    mutable std::condition_variable done;
  };
  std::unique_ptr<Engine> generic_;
  std::shared_ptr<Build> build_;
  Engine* compiled_ = nullptr;        ///< build_->engine once adopted (calling thread only)
  double t0_ = 0, t_end_ = 0, wait_beyond_ = 0;
  bool horizon_ = false;
  long calls_ = 0;
  double wall_start_ = -1;            ///< steady-clock seconds at the first timed call
  double handover_t_;
};

}  // namespace kanegen
