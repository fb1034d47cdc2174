// Explicit embedded Runge-Kutta methods from Boost.Odeint, driven one step at a
// time like the SUNDIALS methods (integrators.cpp): no per-step library
// machinery beyond the stepper itself (no N_Vector, no callbacks through C, no
// linear-solver bookkeeping), so for small non-stiff systems the cost of a
// step is the right-hand side.
//
//   dopri5  Dormand-Prince 5(4), FSAL (6 new rhs evaluations per accepted
//           step), with its own 4th-order dense output for the output times:
//           steps are never cut by output times.
//   rkf78   Runge-Kutta-Fehlberg 7(8), 13 rhs evaluations per step; for tight
//           tolerances. No dense output: an output time inside a step gets
//           one extra step of the same method from the step's start (shorter
//           than the accepted step, so within tolerance); steps themselves
//           are never cut by output times.
//
// Error control: odeint's standard controller (weighted max norm with
// atol + rtol |x|). Failures become IntegrationError with the last accepted
// state: a rhs failure (singular M), a non-finite derivative, too many steps,
// or a step size that no longer advances t.
#include "sim/odeint_integrators.hpp"

#include <fmt/format.h>

#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <vector>

#include "sim/event_location.hpp"
#include "sim/output_schedule.hpp"

namespace kanegen {

namespace odeint = boost::numeric::odeint;

namespace {

using StateVec = std::vector<double>;

/// Thrown by the output callback to stop the integration early.
struct StopRequested {};

/// A non-finite derivative or a recoverable rhs failure inside a step: the
/// step is retried from the last accepted state with a quarter of its size
/// (as SUNDIALS does), at most kMaxRetries times in a row.
struct StepFailed {
  std::string what;
};
constexpr int kMaxRetries = 40;

class OdeintRun {
 public:
  OdeintRun(const OdeProblem& problem, const IntegratorOptions& opt, IntegratorStats& stats)
      : problem_(problem), opt_(opt), stats_(stats), n_(problem.n) {}

  /// x' = f(t, x) for odeint; throws IntegrationError at the last accepted state.
  void rhs(const StateVec& x, StateVec& dxdt, double t) {
    ++stats_.rhs_evals;
    const int rc = problem_.rhs(t, x.data(), dxdt.data());
    if (rc < 0) throw fail(fmt::format("the right-hand side failed (status {}) at t = {}", rc, t));
    if (rc > 0) throw StepFailed{fmt::format("the right-hand side failed (status {}) at t = {}", rc, t)};
    for (int i = 0; i < n_; ++i)
      if (!std::isfinite(dxdt[i]))
        throw StepFailed{
            fmt::format("the right-hand side gave a non-finite derivative (component {}) at t = {}", i, t)};
  }

  /// After a StepFailed: the message of the failure if retrying is hopeless.
  void retry(const StepFailed& f, double h) {
    if (++retries_ > kMaxRetries || !(t_accepted_ + h > t_accepted_))
      throw fail(fmt::format("{} (the step was cut {} times, down to h = {:.3g})", f.what, retries_ - 1, h));
  }
  void step_done() { retries_ = 0; }
  double t_accepted() const { return t_accepted_; }
  const StateVec& x_accepted() const { return x_accepted_; }

  IntegrationError fail(const std::string& what) const {
    return IntegrationError(fmt::format("{}: {}", to_string(opt_.kind), what), t_accepted_,
                            Eigen::Map<const Eigen::VectorXd>(x_accepted_.data(), n_));
  }

  void accepted(double t, const StateVec& x) {
    ++stats_.steps;
    t_accepted_ = t;
    x_accepted_ = x;
    if (opt_.max_steps > 0 && stats_.steps >= opt_.max_steps)
      throw fail(fmt::format("too much work: max_steps = {} steps taken", opt_.max_steps));
  }

  void start(double t0, const StateVec& x0) {
    t_accepted_ = t0;
    x_accepted_ = x0;
  }

  /// Initial step (Hairer, Norsett & Wanner, Sec. II.4): h0 = 0.01 |x| / |f|
  /// in the weighted norm of the error control, at most the horizon.
  double initial_step(double t0, const StateVec& x0, double horizon) {
    StateVec f(n_);
    rhs(x0, f, t0);
    double d0 = 0, d1 = 0;
    for (int i = 0; i < n_; ++i) {
      const double sc = opt_.atol + opt_.rtol * std::abs(x0[i]);
      d0 = std::max(d0, std::abs(x0[i]) / sc);
      d1 = std::max(d1, std::abs(f[i]) / sc);
    }
    const double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    return std::min(h0, horizon);
  }

  /// Calls output at t with x projected; throws StopRequested when it asks to stop.
  /// An event crossed in the last step, (t_a, t_b] with the step's interpolant
  /// `state_at`: the outputs before it, then the event's time and state as the
  /// last output; the run stops (EventReached).
  template <class StateAt>
  void stop_at_event(EventLocator& events, double t_a, double t_b, StateAt state_at, OutputSchedule& schedule,
                     double& tout, const OutputFn& output) {
    const EventLocator::Root root = events.locate(t_a, t_b, [&](double t, double* x) {
      StateVec s(n_);
      state_at(t, s);
      std::copy(s.begin(), s.end(), x);
    });
    stats_.event = root.event;
    stats_.t_event = root.t;
    StateVec xo(n_);
    emit_up_to_event(
        root.t, schedule, tout,
        [&](double t) {
          state_at(t, xo);
          emit(t, xo, output);  // throws StopRequested when the output asks to stop
          return true;
        },
        [&] { emit(root.t, StateVec(root.x.data(), root.x.data() + n_), output); });
    throw StopRequested{};
  }

  void emit(double t, const StateVec& x, const OutputFn& output) {
    Eigen::VectorXd xo = Eigen::Map<const Eigen::VectorXd>(x.data(), n_);
    if (problem_.project) problem_.project(xo.data());
    if (output && !output(t, xo)) throw StopRequested{};
  }

 private:
  const OdeProblem& problem_;
  const IntegratorOptions& opt_;
  IntegratorStats& stats_;
  int n_;
  double t_accepted_ = 0;
  StateVec x_accepted_;
  int retries_ = 0;
};

void run_dopri5(OdeintRun& run, double t0, StateVec x, double t_end, double dt_out, const OutputFn& output,
                const IntegratorOptions& opt, const OdeProblem& problem, double grid_origin) {
  auto sys = [&run](const StateVec& xi, StateVec& dx, double t) { run.rhs(xi, dx, t); };
  auto stepper = odeint::make_dense_output(opt.atol, opt.rtol, odeint::runge_kutta_dopri5<StateVec>());
  run.start(t0, x);
  try {
    stepper.initialize(x, t0, run.initial_step(t0, x, t_end - t0));
  } catch (const StepFailed& f) {
    throw run.fail(f.what);
  }
  run.emit(t0, x, output);
  OutputSchedule schedule(t0, t_end, dt_out, grid_origin);
  EventLocator events(problem);
  events.reset(t0, x.data());
  StateVec xo(x.size());
  double tout = t0;
  while (schedule.next(tout)) {
    while (stepper.current_time() < tout) {
      const double t_before = stepper.current_time();
      try {
        stepper.do_step(sys);
        run.step_done();
      } catch (const odeint::step_adjustment_error& e) {
        throw run.fail(fmt::format("the step size could not be adjusted ({})", e.what()));
      } catch (const StepFailed& f) {
        const double h = stepper.current_time_step() / 4;
        run.retry(f, h);
        stepper.initialize(run.x_accepted(), run.t_accepted(), h);  // re-evaluates f there: succeeded before
        continue;
      }
      if (!(stepper.current_time() > t_before))
        throw run.fail(fmt::format("step size underflow at t = {} (h = {})", t_before, stepper.current_time_step()));
      run.accepted(stepper.current_time(), stepper.current_state());
      if (events.active()) {
        if (events.crossed(stepper.current_time(), stepper.current_state().data()))
          run.stop_at_event(events, t_before, stepper.current_time(),
                            [&](double t, StateVec& s) { stepper.calc_state(t, s); }, schedule, tout, output);
        events.reset(stepper.current_time(), stepper.current_state().data());
      }
    }
    stepper.calc_state(tout, xo);
    run.emit(tout, xo, output);
  }
}

void run_rkf78(OdeintRun& run, double t0, StateVec x, double t_end, double dt_out, const OutputFn& output,
               const IntegratorOptions& opt, const OdeProblem& problem, double grid_origin) {
  auto sys = [&run](const StateVec& xi, StateVec& dx, double t) { run.rhs(xi, dx, t); };
  auto stepper = odeint::make_controlled(opt.atol, opt.rtol, odeint::runge_kutta_fehlberg78<StateVec>());
  odeint::runge_kutta_fehlberg78<StateVec> plain;  // for the output times inside a step
  run.start(t0, x);
  double t = t0, h = run.initial_step(t0, x, t_end - t0);
  double t_prev = t0;
  StateVec x_prev = x, xo;
  run.emit(t0, x, output);
  OutputSchedule schedule(t0, t_end, dt_out, grid_origin);
  EventLocator events(problem);
  events.reset(t0, x.data());
  // inside an accepted step: one step of the same method from its start
  auto inside = [&](double ts, StateVec& s) {
    s = x_prev;
    if (ts == t_prev) return;
    try {
      plain.do_step(sys, s, t_prev, ts - t_prev);
    } catch (const StepFailed& f) {
      throw run.fail(f.what);
    }
  };
  double tout = t0;
  long rejected_in_a_row = 0;
  while (schedule.next(tout)) {
    // steps are cut only at t_end, never at output times: the step sequence
    // (and so the error) does not depend on dt_out
    while (t < tout) {
      const bool cut = h >= t_end - t;
      double h_try = cut ? t_end - t : h;
      const double t_before = t;
      odeint::controlled_step_result result;
      try {
        result = stepper.try_step(sys, x, t, h_try);
      } catch (const StepFailed& f) {
        h = (cut ? t_end - t : h) / 4;
        run.retry(f, h);
        x = run.x_accepted();
        t = run.t_accepted();
        continue;
      }
      run.step_done();
      if (result == odeint::success) {
        if (cut) t = t_end;
        t_prev = run.t_accepted();
        x_prev = run.x_accepted();
        run.accepted(t, x);
        rejected_in_a_row = 0;
        if (!cut || h_try > h) h = h_try;  // a cut step keeps the step the controller had
        if (events.active()) {
          if (events.crossed(t, x.data())) run.stop_at_event(events, t_prev, t, inside, schedule, tout, output);
          events.reset(t, x.data());
        }
      } else {
        h = h_try;
        if (++rejected_in_a_row > 500 || !(t_before + h > t_before))
          throw run.fail(fmt::format("step size underflow at t = {} (h = {})", t_before, h));
      }
    }
    if (tout == t) {
      run.emit(tout, x, output);
    } else {  // inside the last step: one step of the same method from its start
      xo = x_prev;
      try {
        plain.do_step(sys, xo, t_prev, tout - t_prev);
      } catch (const StepFailed& f) {
        throw run.fail(f.what);
      }
      run.emit(tout, xo, output);
    }
  }
}

}  // namespace

IntegratorStats integrate_odeint(const OdeProblem& problem, const IntegratorOptions& opt, double t0,
                                 const Eigen::VectorXd& x0, double t_end, double dt_out, const OutputFn& output,
                                 IntegratorStats stats, double grid_origin) {
  OdeintRun run(problem, opt, stats);
  StateVec x(x0.data(), x0.data() + x0.size());
  try {
    if (opt.kind == IntegratorKind::dopri5)
      run_dopri5(run, t0, std::move(x), t_end, dt_out, output, opt, problem, grid_origin);
    else if (opt.kind == IntegratorKind::rkf78)
      run_rkf78(run, t0, std::move(x), t_end, dt_out, output, opt, problem, grid_origin);
    else
      throw std::logic_error("integrate_odeint called for " + to_string(opt.kind));
  } catch (const StopRequested&) {
  }
  return stats;
}

}  // namespace kanegen
