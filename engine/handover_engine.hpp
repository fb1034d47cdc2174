// An engine that starts on the generic engine and hands over to the model's
// generated code once a background build of it is ready: a first run of a model
// starts integrating at once instead of waiting for the compiler
// (`kanegen simulate --engine auto` when no compiled library is cached).
//
// The build runs in a detached thread of its own and does nothing but build
// (e.g. wait for a background `kanegen compile` process): a run that ends
// first does not wait for it, and the thread touches nothing but its own
// state while the process exits. The calling thread loads the built library
// (milliseconds) at its next call once the thread has said it is done; every
// call checks one atomic flag. The two engines evaluate the same equations
// (they agree to round-off, tests/engine/test_generated_engine.cpp), so a run
// crosses over within its tolerance; it is not bit-for-bit the run of either
// engine alone (docs/decisions.md). Energy and momentum always come from the
// generic engine (they are evaluated at output rows, and the generated code
// has them only when the model's outputs ask). It has no exact Jacobian
// (implicit methods use SUNDIALS' finite differences): a named implicit
// method waits for the build.
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
  /// `build` runs once in the background thread (it may throw: the run then
  /// stays on the generic engine and error() says why); `load` runs in the
  /// calling thread after it and returns the generated engine (it may throw
  /// likewise).
  HandoverEngine(const Model& model, std::function<void()> build, std::function<std::unique_ptr<Engine>()> load);
  /// The same with a build that says when it has started what outlives the process (e.g. a spawned
  /// `kanegen compile`): it calls `started()` then; wait_started() waits for it.
  HandoverEngine(const Model& model, std::function<void(const std::function<void()>& started)> build,
                 std::function<std::unique_ptr<Engine>()> load);
  /// Waits (at most 10 s) until the build has started: a process that ends at once (a short run) would otherwise
  /// end before the build thread spawned what outlives it (`kanegen compile`), and leave no build behind.
  ~HandoverEngine() override;

  /// "generic" before the handover, "generic, then generated from t = 1.25 s" after.
  std::string name() const override;
  /// The run's time span. With it, once the generic engine has run for a
  /// second of wall time, the engine projects the wall time it still needs;
  /// beyond `wait_beyond` seconds it waits (at most `max_wait` seconds) for the
  /// build, which then has the machine, instead of racing it: a long run pays
  /// the compile once and runs the rest fast, a short one never waits. A run
  /// that starts again from an earlier time (simulate's --estimate-error)
  /// projects afresh.
  void set_horizon(double t0, double t_end, double wait_beyond = 30.0, double max_wait = 600.0);
  /// Blocks until the build is done or `seconds` have passed; returns whether it is done.
  bool wait(double seconds = 1e9) const;
  bool build_done() const { return build_->ready.load(std::memory_order_acquire); }
  /// Blocks until the build has started (or is done) or `seconds` have passed; returns whether it has.
  bool wait_started(double seconds = 10.0) const;
  /// Why the build or the load failed ("" while it runs or when it succeeded).
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
  /// The engine to use now (loading the built one when the build is done),
  /// with this engine's inputs and parameters.
  Engine& current(double t);
  /// `e` with this engine's inputs and parameters.
  Engine& synced(Engine& e);
  /// Waits for the build when the generic engine's projected remaining wall time exceeds wait_beyond_.
  void maybe_wait(double t);

  /// Shared with the (detached) build thread, which may outlive the engine.
  struct Build {
    std::function<void(const std::function<void()>& started)> run;
    std::string error;               ///< written by the thread before `ready`
    std::atomic<bool> started{false};
    std::atomic<bool> ready{false};
    mutable std::mutex mutex;
    mutable std::condition_variable done;
  };
  std::unique_ptr<Engine> generic_;
  std::shared_ptr<Build> build_;
  std::function<std::unique_ptr<Engine>()> load_;
  std::unique_ptr<Engine> compiled_;  ///< loaded by the calling thread
  bool load_tried_ = false;
  std::string load_error_;
  double handover_t_;
  double t0_ = 0, t_end_ = 0, wait_beyond_ = 0, max_wait_ = 0;
  bool horizon_ = false;
  long calls_ = 0;
  double last_t_ = -1e300;
  double wall_start_ = -1;            ///< steady-clock seconds at the first timed call of this run
};

}  // namespace kanegen
