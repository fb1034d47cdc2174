#include "engine/handover_engine.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include <fmt/format.h>

#include "engine/generic_engine.hpp"

namespace kanegen {

namespace {
double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

HandoverEngine::HandoverEngine(const Model& model, std::function<void()> build,
                               std::function<std::unique_ptr<Engine>()> load)
    : HandoverEngine(
          model,
          [build = std::move(build)](const std::function<void()>& started) {
            started();
            build();
          },
          std::move(load)) {}

HandoverEngine::HandoverEngine(const Model& model, std::function<void(const std::function<void()>& started)> build,
                               std::function<std::unique_ptr<Engine>()> load)
    : Engine(model),
      generic_(std::make_unique<GenericEngine>(model)),
      build_(std::make_shared<Build>()),
      load_(std::move(load)),
      handover_t_(std::nan("")) {
  build_->run = std::move(build);
  std::thread([b = build_] {
    std::string error;
    try {
      b->run([b] {
        {
          std::lock_guard<std::mutex> lock(b->mutex);
          b->started.store(true, std::memory_order_release);
        }
        b->done.notify_all();
      });
    } catch (const std::exception& ex) {
      error = ex.what();
    } catch (...) {
      error = "unknown failure";
    }
    {
      std::lock_guard<std::mutex> lock(b->mutex);
      b->error = std::move(error);
      b->ready.store(true, std::memory_order_release);
    }
    b->done.notify_all();
  }).detach();
}

bool HandoverEngine::wait(double seconds) const {
  std::unique_lock<std::mutex> lock(build_->mutex);
  return build_->done.wait_for(lock, std::chrono::duration<double>(seconds),
                               [this] { return build_->ready.load(std::memory_order_acquire); });
}

HandoverEngine::~HandoverEngine() { wait_started(10.0); }

bool HandoverEngine::wait_started(double seconds) const {
  std::unique_lock<std::mutex> lock(build_->mutex);
  return build_->done.wait_for(lock, std::chrono::duration<double>(seconds), [this] {
    return build_->started.load(std::memory_order_acquire) || build_->ready.load(std::memory_order_acquire);
  });
}

std::string HandoverEngine::error() const {
  if (!build_done()) return "";
  return !build_->error.empty() ? build_->error : load_error_;
}

std::string HandoverEngine::name() const {
  if (!compiled_) return "generic";
  return fmt::format("generic, then generated from t = {:.6g} s", handover_t_);
}

void HandoverEngine::set_horizon(double t0, double t_end, double wait_beyond, double max_wait) {
  t0_ = t0;
  t_end_ = t_end;
  wait_beyond_ = wait_beyond;
  max_wait_ = max_wait;
  horizon_ = t_end > t0;
}

void HandoverEngine::maybe_wait(double t) {
  if (!horizon_) return;
  if (t < last_t_) {  // a run from an earlier time: project afresh
    wall_start_ = -1;
    calls_ = 0;
  }
  last_t_ = t;
  if ((calls_++ & 255) != 0) return;
  const double now = now_seconds();
  if (wall_start_ < 0) {
    wall_start_ = now;
    t0_ = t;
  }
  const double w = now - wall_start_;
  if (w < 1.0 || !(t > t0_)) return;
  const double remaining = w * (t_end_ - t) / (t - t0_);
  if (remaining <= wait_beyond_) return;
  horizon_ = false;  // decided once
  std::fprintf(stderr,
               "kanegen: at t = %.6g s the generic engine would need about %.0f s more: waiting for the generated "
               "code\n",
               t, remaining);
  wait(max_wait_);
}

Engine& HandoverEngine::current(double t) {
  if (!load_tried_) {
    if (!build_done()) maybe_wait(t);
    if (build_done()) {
      load_tried_ = true;
      if (build_->error.empty()) {
        try {
          compiled_ = load_();
          handover_t_ = t;
        } catch (const std::exception& e) {
          load_error_ = e.what();
        }
      }
    }
  }
  return synced(compiled_ ? *compiled_ : *generic_);
}

Engine& HandoverEngine::synced(Engine& e) {
  if (e.inputs() != inputs()) e.set_inputs(inputs());
  if (e.parameters() != parameters()) e.set_parameters(parameters());
  return e;
}

void HandoverEngine::do_qdot(const VecX& q, const VecX& u, VecX& qd) {
  // q̇ = W(q) u is the same in both and needs no time: the handover waits for a timed call
  (compiled_ ? *compiled_ : *generic_).qdot(q, u, qd);
}
void HandoverEngine::do_mass_matrix(double t, const VecX& q, MatX& M) { current(t).mass_matrix(t, q, M); }
void HandoverEngine::do_forcing(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& F) {
  current(t).forcing(t, q, u, tau, F);
}
void HandoverEngine::do_udot(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& ud) {
  current(t).udot(t, q, u, tau, ud);
}
EnergyValues HandoverEngine::do_energy(double t, const VecX& q, const VecX& u) {
  return synced(*generic_).energy(t, q, u);
}
MomentumValues HandoverEngine::do_momentum(double t, const VecX& q, const VecX& u) {
  return synced(*generic_).momentum(t, q, u);
}
void HandoverEngine::do_reactions(double t, const VecX& q, const VecX& u, const VecX& ud,
                                  std::vector<Reaction>& out) {
  current(t).reactions(t, q, u, ud, out);
}
void HandoverEngine::do_outputs(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& y) {
  current(t).outputs(t, q, u, tau, y);
}

}  // namespace kanegen
