#include "sim/simulate.hpp"

#include "engine/generic_engine.hpp"

#include "engine/model_checks.hpp"

#include "engine/generated_engine.hpp"
#include "model/invariants.hpp"
#include "model/output_file.hpp"
#include "sim/driver_work.hpp"
#include "sim/event_run.hpp"
#include "sim/integrator_choice.hpp"
#include "sim/modal_range.hpp"
#include "sim/work_precision.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

namespace kanegen {

namespace {

/// The free-joint quaternion of x = [q; u] farthest from unit norm.
struct QuatDrift {
  double drift = 0.0;  ///< | |quat| - 1 | (infinite if the norm is not finite)
  double norm = 1.0;
  int body = -1;       ///< index of its body, -1 if none drifted
};

/// Normalizes every quaternion (free and ball joints) in x = [q; u] in place; returns
/// the largest | |quat| - 1 | found (and, if `worst` is given, where).
double normalize_quaternions(const Model& model, double* x, QuatDrift* worst = nullptr) {
  double drift = 0.0;
  for (const auto& slot : model.quaternions) {
    const int i = slot.body;
    double* quat = x + slot.q;
    const double n = std::sqrt(quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2] + quat[3] * quat[3]);
    const double d = std::isfinite(n) ? std::abs(n - 1.0) : std::numeric_limits<double>::infinity();
    if (worst && d > worst->drift) *worst = QuatDrift{d, n, i};
    drift = std::max(drift, d);
    if (n > 0)
      for (int k = 0; k < 4; ++k) quat[k] /= n;
  }
  return drift;
}

/// The largest | |quat| - 1 | of an integrated (unprojected) free-joint
/// quaternion that simulate() accepts at an output (docs/extreme.md). The
/// engines normalize the quaternion, so the drift does not change M or F;
/// but |quat - quat_exact| >= | |quat| - 1 |: it is a lower bound of the
/// error accumulated in the integrated quaternion and a cheap symptom of the
/// attitude error. Past the limit the run stops instead of writing rows.
/// Adaptive methods may drift up to 100 rtol (a loose tolerance asks for a
/// loose result), never less than 1e-6; rk4 projects after every step, so
/// its limit, 1e-6, bounds the drift of one step.
double quaternion_drift_limit(const IntegratorOptions& opt) {
  constexpr double kFloor = 1e-6;
  if (opt.kind == IntegratorKind::rk4) return kFloor;
  return std::max(kFloor, 100.0 * opt.rtol);
}

class ProgressBar {
 public:
  ProgressBar(bool enabled, double t0, double t1) : enabled_(enabled && isatty(2)), t0_(t0), t1_(t1) {}
  void update(double t) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::milliseconds(100) && t < t1_) return;
    last_ = now;
    const double f = t1_ > t0_ ? std::clamp((t - t0_) / (t1_ - t0_), 0.0, 1.0) : 1.0;
    const int w = 40, n = static_cast<int>(f * w);
    fmt::print(stderr, "\r[{}{}] {:5.1f}%  t = {:.6g}", std::string(n, '='), std::string(w - n, ' '), 100 * f, t);
    std::fflush(stderr);
  }
  void finish() {
    if (enabled_) fmt::print(stderr, "\n");
  }

 private:
  bool enabled_;
  double t0_, t1_;
  std::chrono::steady_clock::time_point last_{};
};

}  // namespace

OdeProblem make_ode_problem(Engine& engine, const VecX& tau, std::string* failure, bool use_jacobian,
                            bool stabilize_quaternions) {
  const Model& model = engine.model();
  const int nq = model.nq, nu = model.nu;
  struct Scratch {
    VecX q, u, qdot, udot;
  };
  auto scratch = std::make_shared<Scratch>();
  OdeProblem p;
  p.n = nq + nu;
  // Constraint stabilization of the quaternion norm: + lambda (1 - |q|^2) q,
  // zero on the unit sphere (so q_dot there is exactly W(q) u of the spec)
  // and attracting the integrated quaternion back to it at a rate 2 lambda,
  // lambda = |w| + 1/s: the rotation's own time scale, so it adds no
  // stiffness. Integration error would otherwise let the norm drift.
  std::vector<std::pair<int, int>> free_joints;  // (first quaternion q, first angular speed u)
  if (stabilize_quaternions)
    for (const auto& slot : model.quaternions) free_joints.emplace_back(slot.q, slot.u);
  auto stabilize = [free_joints, nq](const double* x, double* xdot) {
    for (const auto& [iq, iw] : free_joints) {
      const double* quat = x + iq;
      const double* w = x + nq + iw;
      const double lambda = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) + 1.0;
      const double c = lambda * (1.0 - (quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2] + quat[3] * quat[3]));
      for (int k = 0; k < 4; ++k) xdot[iq + k] += c * quat[k];
    }
  };
  // x_dot = f(t, x) around an engine's evaluation `derivative(t, x, xdot)`
  // (which throws SingularMassMatrix): the state and the accelerations checked,
  // the quaternion stabilization added.
  // A gimbal reaching gimbal lock (dynamics.md: |det Gamma| <= 1e-6) stops the
  // run where the lock monitor locates it (run_segments: an event function on
  // every step). The right-hand side refuses states 100x closer to lock (M
  // too ill-conditioned to trust) as a recoverable failure: such a state is a
  // trial stage past the lock (an implicit method's iterate, or the locator's
  // own evaluations at the 1e-6 edge), and the step is retried shorter until
  // an accepted step ends at the crossing, where the monitor stops the run.
  // A singular M within 1e-3 of a joint's lock is that lock's, and likewise.
  const bool has_gimbal = !model.lockable_joints.empty();
  constexpr double kRhsLockGuard = kGimbalLockStop * 1e-2;
  constexpr double kNearLock = 1e-3;
  auto rhs_around = [&](auto derivative) {
    return [derivative, failure, nq, nu, stabilize, has_gimbal, &model](double t, const double* x, double* xdot) -> int {
      for (int i = 0; i < nq + nu; ++i)
        if (!std::isfinite(x[i])) {
          if (failure) *failure = fmt::format("non-finite state at t = {:.17g}", t);
          return -1;
        }
      double measure = 0;
      if (has_gimbal)
        if (const int lb = gimbal_locked_body(model, x, kRhsLockGuard, &measure); lb >= 0) {
          if (failure) *failure = fmt::format("{} at t = {:.17g}", gimbal_lock_message(model, lb, x, measure), t);
          return 1;
        }
      try {
        derivative(t, x, xdot);
      } catch (const SingularMassMatrix& e) {
        if (failure) *failure = fmt::format("{} at t = {:.17g}", e.what(), t);
        return has_gimbal && gimbal_locked_body(model, x, kNearLock, &measure) >= 0 ? 1 : -1;
      }
      stabilize(x, xdot);
      for (int i = nq; i < nq + nu; ++i)
        if (!std::isfinite(xdot[i])) {
          if (failure) *failure = fmt::format("non-finite accelerations at t = {:.17g}", t);
          return 1;  // recoverable: the integrator retries with a smaller step
        }
      return 0;
    };
  };
  // The engines normalize quaternions for M and F; q_dot uses the quaternion
  // as integrated, whose norm the flow quat_dot = 1/2 quat (x) [0, w] preserves.
  auto through_engine = [&engine, tau, scratch, nq, nu](double t, const double* x, double* xdot) {
    Scratch& s = *scratch;
    s.q = Eigen::Map<const VecX>(x, nq);
    s.u = Eigen::Map<const VecX>(x + nq, nu);
    engine.qdot(s.q, s.u, s.qdot);
    engine.udot(t, s.q, s.u, tau, s.udot);
    Eigen::Map<VecX>(xdot, nq) = s.qdot;
    Eigen::Map<VecX>(xdot + nq, nu) = s.udot;
  };
  if (auto* g = dynamic_cast<GeneratedEngine*>(&engine)) {
    // the generated code's own entry: x in, x_dot out, nothing copied; on a
    // failed pivot the engine's own call throws the exception that names it
    p.rhs = rhs_around([g, tau, through_engine](double t, const double* x, double* xdot) {
      // (with joints locked, the engine's reduced u-dot instead)
      if (g->has_locks() || g->state_derivative(t, x, tau.data(), xdot) != 0) through_engine(t, x, xdot);
    });
  } else {
    p.rhs = rhs_around(through_engine);
  }
  p.project = [&model](double* x) { normalize_quaternions(model, x); };
  // the exact Jacobian is the free system's: with joints locked the implicit methods difference the rhs
  if (use_jacobian && engine.jacobian_for_integration() && !engine.has_locks()) {
    auto J = std::make_shared<MatX>(nq + nu, nq + nu);
    p.jacobian = [&engine, tau, scratch, J, failure, nq, nu, free_joints](double t, const double* x, const double*,
                                                                           double* out) -> int {
      Scratch& s = *scratch;
      s.q = Eigen::Map<const VecX>(x, nq);
      s.u = Eigen::Map<const VecX>(x + nq, nu);
      try {
        if (!engine.jacobian(t, s.q, s.u, tau, *J)) return -1;
      } catch (const SingularMassMatrix& e) {
        if (failure) *failure = fmt::format("{} at t = {:.17g}", e.what(), t);
        return -1;
      }
      // plus the derivative of the quaternion stabilization term of the rhs
      for (const auto& [iq, iw_u] : free_joints) {
        const int iw = nq + iw_u;
        const Eigen::Vector4d quat = s.q.segment<4>(iq);
        const Eigen::Vector3d w = s.u.segment<3>(iw_u);
        const double lambda = w.norm() + 1.0, c = 1.0 - quat.squaredNorm();
        J->block<4, 4>(iq, iq) += lambda * (c * Eigen::Matrix4d::Identity() - 2.0 * quat * quat.transpose());
        if (w.norm() > 0) J->block<4, 3>(iq, iw) += c * quat * (w / w.norm()).transpose();
      }
      Eigen::Map<MatX>(out, nq + nu, nq + nu) = *J;
      return J->allFinite() ? 0 : 1;
    };
  }
  return p;
}

std::vector<std::string> csv_columns(const Model& model) {
  std::vector<std::string> cols{"t"};
  cols.insert(cols.end(), model.q_names.begin(), model.q_names.end());
  cols.insert(cols.end(), model.prescribed_names.begin(), model.prescribed_names.end());
  cols.insert(cols.end(), model.u_names.begin(), model.u_names.end());
  if (model.outputs.energy) cols.insert(cols.end(), {"T", "V"});
  if (model.outputs.momentum) cols.insert(cols.end(), {"Hx", "Hy", "Hz"});
  if (model.outputs.reactions)
    for (const Body& b : model.bodies)
      for (const char* s : {".fx", ".fy", ".fz", ".tx", ".ty", ".tz"}) cols.push_back(b.name + s);
  cols.insert(cols.end(), model.input_names.begin(), model.input_names.end());
  cols.insert(cols.end(), model.output_names.begin(), model.output_names.end());
  return cols;
}

namespace {

/// In a central field: where a drift stands against the round-off of the orbit's digits, sqrt(steps)
/// ulps of the total with the orbit (docs/decisions.md, "Reports in orbit").
std::string orbit_roundoff(double drift, double total, long steps) {
  const double ulp = std::numeric_limits<double>::epsilon() * std::abs(total);
  if (!(ulp > 0) || steps <= 0) return "";
  const double floor = ulp * std::sqrt(static_cast<double>(steps));
  return fmt::format("; {:.0f} ulps of that total, its round-off over {} steps ~{:.0f} ulps{}", drift / ulp, steps,
                     floor / ulp,
                     drift <= 10.0 * floor ? ": at the orbit's round-off, no measure of the attitude's accuracy "
                                             "(--estimate-error measures it)"
                                           : "");
}

}  // namespace

std::string RunQuality::summary() const {
  std::vector<std::string> parts;
  if (std::isfinite(energy_drift))
    parts.push_back(about_com ? fmt::format("energy drift {:.2e} J: {:.2e} of the motion about the centre of mass "
                                            "(T_c up to {:.3e} J; |E| with the orbit's {:.3e} J{})",
                                            energy_drift_J, energy_drift, energy_scale_J, energy_total_J,
                                            orbit_roundoff(energy_drift_J, energy_total_J, steps))
                              : fmt::format("energy drift {:.2e} ({:.2e} J)", energy_drift, energy_drift_J));
  if (std::isfinite(energy_balance))
    parts.push_back(fmt::format("energy balance with the drivers' work {:.2e} (their work by quadrature on the "
                                "output rows, good to about {:.1e}: a smaller --dt-out tightens it)",
                                energy_balance, energy_balance_quadrature));
  if (std::isfinite(H_drift)) {
    const char* H = H_z ? "H_z" : "|H|";
    parts.push_back(about_com ? fmt::format("{} drift {:.2e} N m s: {:.2e} of the motion about the centre of mass "
                                            "(scale {:.3e} N m s; {} with the orbit's {:.3e} N m s{})",
                                            H, H_drift_Nms, H_drift, H_scale_Nms, H, H_total_Nms,
                                            orbit_roundoff(H_drift_Nms, H_total_Nms, steps))
                              : fmt::format("{} drift {:.2e} ({:.2e} N m s against a scale of {:.3e})", H, H_drift,
                                            H_drift_Nms, H_scale_Nms));
  }
  if (std::isfinite(error_estimate))
    parts.push_back(fmt::format("estimated error {:.2e} ({})", error_estimate, error_worst));
  std::string out;
  for (const auto& p : parts) out += (out.empty() ? "" : ", ") + p;
  if (parts.empty())
    return invariants_note.empty() ? "no error measure: --estimate-error gives an error estimate"
                                   : invariants_note + "; --estimate-error gives an error estimate";
  return invariants_note.empty() ? out : out + " (" + invariants_note + ")";
}

namespace {

/// At most this many output states are kept for the drift and the error estimate.
constexpr double kMaxKeptStates = 2000;

/// The states at every `stride`-th output time, and those it must keep (the
/// last one, the states just before and after an event); where each segment
/// between events begins, and its locks.
struct SampledRun {
  long stride = 1, k = 0;
  bench::Trajectory traj;
  std::vector<std::size_t> segment_begin{0};
  std::vector<LockSet> segment_locks;
  void add(double t, const VecX& x, bool keep) {
    if (k++ % stride == 0 || keep) {
      traj.t.push_back(t);
      traj.x.push_back(x);
    }
  }
  void new_segment(const LockSet& locks) {
    segment_begin.push_back(traj.t.size());
    segment_locks.push_back(locks);
  }
  bench::Trajectory segment(std::size_t i) const {
    bench::Trajectory s;
    const std::size_t a = segment_begin[i], b = i + 1 < segment_begin.size() ? segment_begin[i + 1] : traj.t.size();
    s.t.assign(traj.t.begin() + a, traj.t.begin() + b);
    s.x.assign(traj.x.begin() + a, traj.x.begin() + b);
    return s;
  }
};

/// Integrates from `initial` to t_end segment by segment: a segment ends at
/// the next event (model.events: a time event, or a crossing the integrator
/// locates) and, with a digital controller (sample_period > 0), at the next
/// sample. At an event the state just before and just after are both rows
/// (`row(t, x, true)`); at a sample time the next segment starts with the
/// inputs the law set there (`at_sample`), one row if on the output grid.
/// `problem()` builds the ODE for the engine's current locks and inputs.
struct SegmentHooks {
  std::function<OdeProblem()> problem;
  std::function<void(double t, const VecX& x)> at_sample;
  std::function<void(double t, const VecX& x, bool keep)> row;
  std::function<void(const LockSet& locks)> new_segment;
};

/// A joint watched for gimbal lock over a segment: g = det Gamma - s 1e-6,
/// s its sign at the segment's start, changes sign where |det Gamma| falls to
/// kGimbalLockStop on the side it started, or where det Gamma passes through
/// zero within a step (the step's interpolant locates it, as an event).
struct LockMonitor {
  int body = -1;
  double sign = 1;
};

/// Appends one event function per free lockable joint to `p` (after the
/// model's events) and returns them in that order.
std::vector<LockMonitor> watch_gimbal_lock(const Model& model, const LockSet& locks, const VecX& x, OdeProblem& p) {
  std::vector<LockMonitor> monitors;
  for (const int b : model.lockable_joints) {
    if (!locks.empty() && locks[b]) continue;  // a locked joint does not move
    const double det = joint_lock_determinant(model.bodies[b].joint, x.data() + model.bodies[b].q_joint);
    monitors.push_back({b, det < 0 ? -1.0 : 1.0});
  }
  if (monitors.empty()) return monitors;
  const int n_before = p.n_events;
  auto before = p.events;
  p.n_events = n_before + static_cast<int>(monitors.size());
  p.events = [before, n_before, monitors, &model](double t, const double* x, double* g) {
    if (before) before(t, x, g);
    for (std::size_t k = 0; k < monitors.size(); ++k) {
      const Body& b = model.bodies[monitors[k].body];
      g[n_before + static_cast<int>(k)] = joint_lock_determinant(b.joint, x + b.q_joint) - monitors[k].sign * kGimbalLockStop;
    }
  };
  return monitors;
}

IntegratorStats run_segments(Engine& engine, const State& initial, double t_end, double dt_out, double sample_period,
                             const IntegratorOptions& opt, EventRun& events, long& segments, const SegmentHooks& h) {
  const double t0 = initial.t;
  double t = t0;
  VecX x(engine.model().nq + engine.model().nu);
  x << initial.q, initial.u;
  IntegratorStats total;
  total.integrator = to_string(opt.kind);
  const double T = sample_period;
  const double tol = 1e-9 * std::min(dt_out, T > 0 ? T : dt_out) +
                     16 * std::numeric_limits<double>::epsilon() * std::max(std::abs(t0), std::abs(t_end));
  auto on_grid = [&](double ts) {
    const double k = (ts - t0) / dt_out;
    return std::abs(k - std::round(k)) <= 1e-9 * std::max(1.0, std::abs(k));
  };
  long k_sample = 0;  // the last sample: t0 + k_sample T
  bool start_row = true;
  segments = 0;
  if (events.time_event_due(t) && t < t_end) {  // events at the start: a row before, then the run from after
    h.row(t, x, true);
    events.fire(engine, t, x, -1);
    h.new_segment(events.locks());
  }
  for (;;) {
    double t_stop = events.next_stop(t, t_end);
    bool sample_now = false;
    if (T > 0) {
      while (t0 + static_cast<double>(k_sample + 1) * T <= t + tol) ++k_sample;
      sample_now = std::abs(t - (t0 + static_cast<double>(k_sample) * T)) <= tol;
      const double next_sample = t0 + static_cast<double>(k_sample + 1) * T;
      if (next_sample < t_stop - tol) t_stop = next_sample;
    }
    if (sample_now) h.at_sample(t, x);
    OdeProblem p = h.problem();
    events.arm(p);
    const int n_model_events = p.n_events;
    const std::vector<LockMonitor> monitors = watch_gimbal_lock(engine.model(), events.locks(), x, p);
    bool first = true, pending = false;
    double tp = t;
    VecX xp = x;
    const IntegratorStats s = integrate(
        p, opt, t, x, t_stop, dt_out,
        [&](double ts, const VecX& xs) {
          if (first) {
            first = false;
            if (start_row) h.row(ts, xs, true);
            return true;
          }
          if (pending) h.row(tp, xp, false);
          tp = ts;
          xp = xs;
          pending = true;
          return true;
        },
        t0);
    ++segments;
    total.steps += s.steps;
    total.rhs_evals += s.rhs_evals;
    total.jac_evals += s.jac_evals;
    total.error_test_failures += s.error_test_failures;
    total.nonlinear_failures += s.nonlinear_failures;
    total.wall_seconds += s.wall_seconds;
    t = pending ? tp : t_stop;
    x = xp;
    if (s.event >= n_model_events) {  // a joint reached gimbal lock: located on the step, the run fails there
      const Body& b = engine.model().bodies[monitors[s.event - n_model_events].body];
      throw IntegrationError(
          fmt::format("{}: the {} joint of '{}' reached gimbal lock at t = {:.17g} (|det Gamma| = {:.3g} <= {:.0e}, "
                      "located on the step; dynamics.md, Joints)",
                      to_string(opt.kind), to_string(b.joint.type), b.name, t,
                      std::abs(joint_lock_determinant(b.joint, x.data() + b.q_joint)), kGimbalLockStop),
          t, x);
    }
    const bool at_end = !(t < t_end - tol);
    if (s.event >= 0 || events.time_event_due(t)) {  // an event at t_end fires too (two rows there)
      h.row(t, x, true);  // just before
      events.fire(engine, t, x, s.event);
      h.new_segment(events.locks());
      start_row = true;   // just after: the next segment's first row
      if (at_end) {
        h.row(t, x, true);
        break;
      }
      continue;
    }
    if (at_end) {
      h.row(t, x, true);
      break;
    }
    start_row = on_grid(t);  // a sample time: one row, with the inputs the law sets there
  }
  return total;
}

long stride_for(const State& initial, const SimulationOptions& o) {
  const double rows = std::floor((o.t_end - initial.t) / o.dt_out) + 2;
  return std::max(1L, static_cast<long>(std::ceil(rows / kMaxKeptStates)));
}

}  // namespace

SimulationResult simulate(Engine& engine, const State& initial, const SimulationOptions& options_in,
                          RowSink& sink) {
  const Model& model = engine.model();
  const int nq = model.nq, nu = model.nu;
  SimulationOptions options = options_in;
  RunQuality quality;
  if (options.integrator.kind == IntegratorKind::automatic) {
    const IntegratorChoice c =
        choose_integrator(engine, initial, options.t_end, options.dt_out, options.integrator.rtol);
    options.integrator.kind = c.kind;
    quality.integrator_choice = c.reason;
  }
  SampledRun sampled;
  sampled.stride = stride_for(initial, options);
  std::string failure;
  const Controller& controller = options.controller;
  const bool digital = controller && controller.period > 0;
  if (controller && !(controller.period >= 0 && std::isfinite(controller.period)))
    throw std::invalid_argument(fmt::format("controller period {} s; expected 0 (continuous) or a positive period",
                                            controller.period));
  if (digital) {  // samples and output times on one grid
    const double r = controller.period / options.dt_out, r_inv = options.dt_out / controller.period;
    if (std::abs(r - std::round(r)) > 1e-9 * r && std::abs(r_inv - std::round(r_inv)) > 1e-9 * r_inv)
      throw std::invalid_argument(fmt::format("controller period {} s and output step {} s: one must be a multiple "
                                              "of the other",
                                              controller.period, options.dt_out));
  }
  engine.set_inputs(initial.w);
  // A continuous controller's feedback is not in the engine's Jacobian: the
  // implicit methods then difference the right-hand side.
  auto base_problem = [&] {
    return make_ode_problem(engine, initial.tau, &failure, options.use_jacobian && !controller,
                            options.integrator.kind != IntegratorKind::rk4);
  };
  VecX y(model.ny), w_ctl(model.nw), q_ctl(nq), u_ctl(nu);
  // the law at (t, x): the outputs with the inputs held so far, then the new inputs
  auto apply_law = [&](double t, const double* x) {
    q_ctl = Eigen::Map<const VecX>(x, nq);
    u_ctl = Eigen::Map<const VecX>(x + nq, nu);
    normalize_quaternions(model, q_ctl.data());  // the quaternions lie in q
    if (model.ny > 0) engine.outputs(t, q_ctl, u_ctl, initial.tau, y);
    w_ctl = engine.inputs();
    controller.law(t, q_ctl, u_ctl, y, w_ctl);
    engine.set_inputs(w_ctl);
  };
  auto with_law = [&](OdeProblem problem) {
    if (controller && !digital) {
      auto base = problem.rhs;
      problem.rhs = [&, base](double t, const double* x, double* xdot) -> int {
        try {
          apply_law(t, x);
        } catch (const SingularMassMatrix& e) {
          failure = fmt::format("{} at t = {:.17g} (while computing the controller's outputs)", e.what(), t);
          return -1;
        }
        return base(t, x, xdot);
      };
    }
    return problem;
  };

  SimulationResult result;
  const auto cols = csv_columns(model);
  sink.begin(cols);

  ProgressBar bar(options.progress, initial.t, options.t_end);
  VecX q(nq), u(nu), udot(nu);
  std::vector<Reaction> reactions;
  std::vector<double> row;

  // Checks on every output row, before it is written (a row with a bad value
  // is never written; simulate_to_file then removes the whole file):
  //  - the quaternion norm drift of the integrated state (see project below);
  //  - every value of the row finite (state, energy, momentum, reactions);
  //  - a singular M while computing the reactions.
  // Each failure is an IntegrationError with the time and the state there
  // (the unprojected state for a drifted quaternion).
  const double drift_limit = quaternion_drift_limit(options.integrator);
  QuatDrift pending;       // worst drift above the limit seen since the last output
  VecX pending_raw;        // the unprojected state where it was seen
  bool output_failure = false;  // the error comes from these checks, not from the integrator
  auto fail_at = [&](double t, const VecX& x, const std::string& what) {
    output_failure = true;
    return IntegrationError(fmt::format("{}: output check failed at t = {:.17g}: {}",
                                        to_string(options.integrator.kind), t, what),
                            t, x);
  };
  const std::vector<int>& gimbals = model.lockable_joints;
  std::vector<int> gimbal_sign(gimbals.size(), 0);  // det Gamma's sign at the last row
  double last_row_t = initial.t;
  auto column_of = [&](std::size_t k) { return k < cols.size() ? cols[k] : fmt::format("column {}", k); };

  // The invariants the scene's physics keeps (model/invariants.hpp), and why not the others; with prescribed
  // motion alone doing work, E - E0 = the drivers' work, measured at every row on the generic engine (it has the
  // reactions at any state)
  const Invariants physics = invariants_of(model, initial.tau, initial.w, static_cast<bool>(controller));
  std::unique_ptr<GenericEngine> driver_engine;
  std::unique_ptr<DriverWorkMeter> drivers;
  if (physics.energy_with_drivers) {
    driver_engine = std::make_unique<GenericEngine>(model);
    driver_engine->set_parameters(engine.parameters());
    driver_engine->set_inputs(initial.w);
    driver_engine->set_locks(initial.locked);
    drivers = std::make_unique<DriverWorkMeter>(*driver_engine, initial.tau);
  }
  ModalRange modal_range(model);
  auto write = [&](double t, const VecX& x, bool keep) -> bool {
    // x arrives projected; the drift was measured on the raw state by project below.
    if (pending.body >= 0) {
      const Body& b = model.bodies[pending.body];
      const bool rk4 = options.integrator.kind == IntegratorKind::rk4;
      throw fail_at(t, pending_raw,
                    fmt::format("quaternion of free body '{}' has norm {:.17g} (| |q| - 1 | = {:.6g} > {:.3g}{}): the "
                                "integrated attitude has drifted at least this much; {}",
                                b.name, pending.norm, pending.drift, drift_limit,
                                rk4 ? ", after one step" : ", the limit for this rtol",
                                rk4 ? "reduce the step (--h)" : "tighten --rtol/--atol"));
    }
    // a gimbal whose det Gamma changed sign since the last row passed through gimbal lock
    for (std::size_t g = 0; g < gimbals.size(); ++g) {
      const Body& b = model.bodies[gimbals[g]];
      const double det = joint_lock_determinant(b.joint, x.data() + b.q_joint);
      if (gimbal_sign[g] != 0 && det * gimbal_sign[g] < 0)
        throw fail_at(t, x, fmt::format("the {} joint of '{}' passed through gimbal lock (det Gamma changed sign "
                                        "since t = {:.17g}; now {:.3g})",
                                        to_string(b.joint.type), b.name, last_row_t, det));
      gimbal_sign[g] = det > 0 ? 1 : det < 0 ? -1 : 0;
    }
    last_row_t = t;
    q = x.head(nq);
    u = x.tail(nu);
    modal_range.add(t, q);
    row.assign(1, t);
    row.insert(row.end(), x.data(), x.data() + nq);
    for (const Body& b : model.bodies)  // the prescribed coordinates, after the q's
      if (b.joint.prescribed()) row.push_back(b.joint.motion->at(t).f);
    row.insert(row.end(), x.data() + nq, x.data() + nq + nu);
    try {
      if (model.outputs.energy) {
        const EnergyValues E = engine.energy(t, q, u);
        row.insert(row.end(), {E.T, E.V});
      }
      if (model.outputs.momentum) {
        const MomentumValues P = engine.momentum(t, q, u);
        row.insert(row.end(), {P.H_N(0), P.H_N(1), P.H_N(2)});
      }
      if (model.outputs.reactions) {
        engine.udot(t, q, u, initial.tau, udot);
        engine.reactions(t, q, u, udot, reactions);
        for (const Reaction& r : reactions)
          row.insert(row.end(), {r.force_B(0), r.force_B(1), r.force_B(2), r.torque_B(0), r.torque_B(1), r.torque_B(2)});
      }
      if (controller && !digital) apply_law(t, x.data());  // the inputs at this time
      row.insert(row.end(), engine.inputs().data(), engine.inputs().data() + model.nw);
      if (model.ny > 0) {
        engine.outputs(t, q, u, initial.tau, y);
        row.insert(row.end(), y.data(), y.data() + model.ny);
      }
    } catch (const SingularMassMatrix& e) {
      throw fail_at(t, x, fmt::format("{} (while computing the reactions or outputs)", e.what()));
    }
    for (std::size_t k = 0; k < row.size(); ++k)
      if (!std::isfinite(row[k]))
        throw fail_at(t, x, fmt::format("non-finite value {} in column '{}'", row[k], column_of(k)));
    sampled.add(t, x, keep);
    if (drivers) drivers->add(t, q, u);
    sink.row(row.data(), row.size());
    ++result.rows;
    bar.update(t);
    return true;
  };
  // The ODE of a segment (for the engine's locks and inputs then). Drift is
  // measured on the unprojected state: project is wrapped (it is called on
  // every output state, and after every rk4 step).
  const auto run_start = std::chrono::steady_clock::now();
  auto make_problem = [&] {
    OdeProblem problem = with_law(base_problem());
    if (options.wall_time_limit > 0) {  // a run that would hang: checked every 64 evaluations
      auto base = problem.rhs;
      auto calls = std::make_shared<long>(0);
      const double limit = options.wall_time_limit;
      problem.rhs = [&, base, calls, limit](double t, const double* x, double* xdot) -> int {
        if (++*calls % 64 == 0 &&
            std::chrono::duration<double>(std::chrono::steady_clock::now() - run_start).count() > limit) {
          failure = fmt::format("the run exceeded its wall-time limit of {} s at t = {:.17g}", limit, t);
          return -1;
        }
        return base(t, x, xdot);
      };
    }
    auto project = problem.project;
    problem.project = [&, project](double* x) {
      VecX raw = Eigen::Map<VecX>(x, nq + nu);
      QuatDrift worst;
      result.max_quaternion_drift =
          std::max(result.max_quaternion_drift, normalize_quaternions(model, raw.data(), &worst));
      if (worst.body >= 0 && !(worst.drift <= drift_limit) && pending.body < 0) {
        pending = worst;
        pending_raw = Eigen::Map<VecX>(x, nq + nu);
      }
      project(x);
    };
    return problem;
  };
  // the locks at the start, and back as they were after the run
  const ScopedLocks locks(engine, initial.locked);
  sampled.segment_locks.push_back(engine.locks());
  const std::vector<Event>* run_events = options.events ? &*options.events : nullptr;
  EventRun events(model, initial.t, initial.locked, run_events);
  SegmentHooks hooks;
  hooks.problem = make_problem;
  hooks.at_sample = [&](double t, const VecX& x) {
    try {
      apply_law(t, x.data());
    } catch (const SingularMassMatrix& e) {
      throw IntegrationError(fmt::format("{} (while computing the controller's outputs)", e.what()), t, x);
    }
  };
  hooks.row = [&](double t, const VecX& x, bool keep) { write(t, x, keep); };
  hooks.new_segment = [&](const LockSet& l) {
    sampled.new_segment(l);
    if (drivers) drivers->new_segment(l);
  };
  try {
    result.stats = run_segments(engine, initial, options.t_end, options.dt_out, digital ? controller.period : 0.0,
                                options.integrator, events, result.segments, hooks);
  } catch (const IntegrationError& e) {
    bar.finish();
    if (output_failure || failure.empty()) throw;
    throw IntegrationError(fmt::format("{} ({})", e.reason, failure), e.t, e.x);
  }
  bar.finish();

  quality.invariants_note = physics.note();
  quality.warnings = modal_range.warnings();
  if (physics.energy || physics.angular_momentum || physics.angular_momentum_z) {
    // simulate reports H (or H_z with J2), not p
    const bench::InvariantSet inv{physics.energy, physics.angular_momentum, physics.angular_momentum_z};
    // Generated code has only the energy and momentum the model's outputs ask
    // for; the invariants are then measured on the generic engine, at the same
    // states (a few evaluations per output row, after the run).
    // (H_z alone too; and in orbit the scales T_c, H_c need both: sim/motion_about_com)
    const bool lacks = (inv.energy || inv.momentum || inv.momentum_z) && dynamic_cast<GeneratedEngine*>(&engine) &&
                       !(model.outputs.energy && model.outputs.momentum);
    std::unique_ptr<GenericEngine> measure;
    if (lacks) {
      measure = std::make_unique<GenericEngine>(model);
      measure->set_parameters(engine.parameters());
    }
    // between events (a latch loses energy; a joint to ground locked holds the momentum)
    for (std::size_t i = 0; i < sampled.segment_begin.size(); ++i) {
      const bench::Trajectory seg = sampled.segment(i);
      if (seg.t.size() < 2) continue;
      bench::InvariantSet inv_i = inv;
      const LockSet& l = sampled.segment_locks[i];
      for (std::size_t b = 0; b < l.size(); ++b)
        if (l[b] && model.bodies[b].parent < 0) inv_i.momentum = inv_i.momentum_z = false;
      const bench::Drifts d = bench::invariant_drifts(lacks ? *measure : engine, inv_i, seg);
      if (bench::worse_measure(quality.energy_drift, d.energy) != quality.energy_drift) {
        quality.energy_drift = d.energy;
        quality.energy_drift_J = d.energy_abs;
        quality.energy_scale_J = d.energy_scale;
        quality.energy_total_J = d.E_total;
      }
      if (bench::worse_measure(quality.H_drift, d.H) != quality.H_drift) {
        quality.H_drift = d.H;
        quality.H_drift_Nms = d.H_abs;
        quality.H_scale_Nms = d.H_scale;
        quality.H_total_Nms = d.H_total;
      }
      quality.about_com = d.about_com;
      quality.H_z = d.H_z;
    }
  }
  if (drivers) {
    const EnergyBalance b = drivers->balance();
    quality.energy_balance = b.residual;
    quality.energy_balance_quadrature = b.quadrature;
  }
  if (options.estimate_error && controller) {
    quality.error_worst = "no error estimate with a controller in the loop (its state would be run twice)";
  } else if (options.estimate_error) {
    // the same method at tolerances 100 times tighter, at the same output times
    IntegratorOptions tight = options.integrator;
    tight.rtol /= 100;
    tight.atol /= 100;
    tight.h /= 10;  // rk4: error / 1e4
    tight.max_steps = 0;
    SampledRun ref;
    ref.stride = sampled.stride;
    std::string f2;
    SegmentHooks h2;
    h2.problem = [&] {
      return make_ode_problem(engine, initial.tau, &f2, options.use_jacobian,
                              options.integrator.kind != IntegratorKind::rk4);
    };
    h2.at_sample = [](double, const VecX&) {};
    h2.row = [&](double t, const VecX& x, bool keep) { ref.add(t, x, keep); };
    h2.new_segment = [&](const LockSet& l) { ref.new_segment(l); };
    try {
      engine.set_locks(initial.locked);
      EventRun events2(model, initial.t, initial.locked, run_events);
      long segments2 = 0;
      run_segments(engine, initial, options.t_end, options.dt_out, 0.0, tight, events2, segments2, h2);
      if (ref.traj.t.size() != sampled.traj.t.size())
        throw IntegrationError(fmt::format("its events fired differently ({} states kept against {})",
                                           ref.traj.t.size(), sampled.traj.t.size()),
                               options.t_end, VecX());
      const bench::ErrorMeasure e = bench::trajectory_error(model, sampled.traj, ref.traj);
      quality.error_estimate = e.error;
      quality.error_worst = fmt::format("{} at t = {:.6g}", e.worst, e.worst_t);
    } catch (const IntegrationError& e) {
      quality.error_worst = fmt::format("the tighter run failed: {}", e.reason);
    }
  }
  quality.steps = result.stats.steps;
  result.quality = quality;
  result.events = events.fired();
  return result;
}

SimulationResult simulate(Engine& engine, const State& initial, const SimulationOptions& options, std::ostream& csv) {
  CsvRowWriter writer(csv);
  return simulate(engine, initial, options, writer);
}

SimulationResult simulate_to_file(Engine& engine, const State& initial, const SimulationOptions& options,
                                  const std::string& path) {
  OutputFile out(path);  // the file appears only if the whole run succeeded
  const SimulationResult r = simulate(engine, initial, options, out.stream());
  out.commit();
  return r;
}

}  // namespace kanegen
