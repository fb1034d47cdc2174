#include "sim/simulate.hpp"

#include "engine/generic_engine.hpp"

#include "engine/model_checks.hpp"

#include "engine/generated_engine.hpp"
#include "model/output_file.hpp"
#include "sim/integrator_choice.hpp"
#include "sim/work_precision.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
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
  // A gimbal reaching gimbal lock (dynamics.md: |det Gamma| <= 1e-6) stops the run.
  const bool has_gimbal = !model.lockable_joints.empty();
  auto rhs_around = [&](auto derivative) {
    return [derivative, failure, nq, nu, stabilize, has_gimbal, &model](double t, const double* x, double* xdot) -> int {
      for (int i = 0; i < nq + nu; ++i)
        if (!std::isfinite(x[i])) {
          if (failure) *failure = fmt::format("non-finite state at t = {:.17g}", t);
          return -1;
        }
      double measure = 0;
      if (has_gimbal)
        if (const int lb = gimbal_locked_body(model, x, kGimbalLockStop, &measure); lb >= 0) {
          if (failure) *failure = fmt::format("{} at t = {:.17g}", gimbal_lock_message(model, lb, x, measure), t);
          return -1;
        }
      try {
        derivative(t, x, xdot);
      } catch (const SingularMassMatrix& e) {
        if (failure) *failure = fmt::format("{} at t = {:.17g}", e.what(), t);
        return -1;
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
      if (g->state_derivative(t, x, tau.data(), xdot) != 0) through_engine(t, x, xdot);
    });
  } else {
    p.rhs = rhs_around(through_engine);
  }
  p.project = [&model](double* x) { normalize_quaternions(model, x); };
  if (use_jacobian && engine.has_jacobian()) {
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

std::string RunQuality::summary() const {
  std::vector<std::string> parts;
  if (std::isfinite(energy_drift)) parts.push_back(fmt::format("energy drift {:.2e}", energy_drift));
  if (std::isfinite(H_drift)) parts.push_back(fmt::format("|H| drift {:.2e}", H_drift));
  if (std::isfinite(error_estimate))
    parts.push_back(fmt::format("estimated error {:.2e} ({})", error_estimate, error_worst));
  if (parts.empty()) return "no invariant holds here: --estimate-error gives an error estimate";
  std::string out;
  for (const auto& p : parts) out += (out.empty() ? "" : ", ") + p;
  return out;
}

namespace {

/// At most this many output states are kept for the drift and the error estimate.
constexpr double kMaxKeptStates = 2000;

/// The states at every `stride`-th output time, and the last one.
struct SampledRun {
  long stride = 1, k = 0;
  bench::Trajectory traj;
  void add(double t, const VecX& x, bool last) {
    if (k++ % stride == 0 || last) {
      traj.t.push_back(t);
      traj.x.push_back(x);
    }
  }
};

long stride_for(const State& initial, const SimulationOptions& o) {
  const double rows = std::floor((o.t_end - initial.t) / o.dt_out) + 2;
  return std::max(1L, static_cast<long>(std::ceil(rows / kMaxKeptStates)));
}

}  // namespace

SimulationResult simulate(Engine& engine, const State& initial, const SimulationOptions& options_in,
                          std::ostream& csv) {
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
  OdeProblem problem = make_ode_problem(engine, initial.tau, &failure, options.use_jacobian && !controller,
                                        options.integrator.kind != IntegratorKind::rk4);
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
  VecX x0(nq + nu);
  x0 << initial.q, initial.u;

  SimulationResult result;
  const auto cols = csv_columns(model);
  for (std::size_t c = 0; c < cols.size(); ++c) csv << (c ? "," : "") << cols[c];
  csv << '\n';

  ProgressBar bar(options.progress, initial.t, options.t_end);
  VecX q(nq), u(nu), udot(nu);
  std::vector<Reaction> reactions;
  std::vector<double> row;
  std::string line;

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

  auto write = [&](double t, const VecX& x) -> bool {
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
    row.assign(x.data(), x.data() + nq);
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
        throw fail_at(t, x, fmt::format("non-finite value {} in column '{}'", row[k], column_of(k + 1)));
    sampled.add(t, x, !(t < options.t_end));
    line = fmt::format("{:.17g}", t);
    for (double v : row) line += fmt::format(",{:.17g}", v);
    csv << line << '\n';
    ++result.rows;
    bar.update(t);
    return true;
  };
  // Drift is measured on the unprojected state: wrap project (called on every
  // output state, and after every rk4 step).
  auto project = problem.project;
  problem.project = [&](double* x) {
    VecX raw = Eigen::Map<VecX>(x, nq + nu);
    QuatDrift worst;
    result.max_quaternion_drift = std::max(result.max_quaternion_drift, normalize_quaternions(model, raw.data(), &worst));
    if (worst.body >= 0 && !(worst.drift <= drift_limit) && pending.body < 0) {
      pending = worst;
      pending_raw = Eigen::Map<VecX>(x, nq + nu);
    }
    project(x);
  };
  try {
    if (!digital) {
      result.stats = integrate(problem, options.integrator, initial.t, x0, options.t_end, options.dt_out, write);
    } else {
      // A digital controller: one integration per sample period, restarted at
      // each sample with the inputs the law set there (zero-order hold).
      const double T = controller.period, t0 = initial.t;
      const double dt_seg = std::min(options.dt_out, T);
      auto on_output_grid = [&](double t) {
        const double k = (t - t0) / options.dt_out;
        return std::abs(k - std::round(k)) <= 1e-9 * std::max(1.0, std::abs(k));
      };
      VecX x = x0, x_end = x0;
      result.stats.integrator = to_string(options.integrator.kind);
      for (long k = 0;; ++k) {
        const double t_a = t0 + static_cast<double>(k) * T;
        if (!(t_a < options.t_end)) break;
        const double t_b = std::min(t0 + static_cast<double>(k + 1) * T, options.t_end);
        const bool last = !(t_b < options.t_end) || t_b + 1e-12 * std::max(1.0, std::abs(t_b)) >= options.t_end;
        try {
          apply_law(t_a, x.data());
        } catch (const SingularMassMatrix& e) {
          throw IntegrationError(fmt::format("{} (while computing the controller's outputs)", e.what()), t_a, x);
        }
        const IntegratorStats s =
            integrate(problem, options.integrator, t_a, x, last ? options.t_end : t_b, dt_seg,
                      [&](double t, const VecX& xs) {
                        const bool end = !(t < (last ? options.t_end : t_b));
                        if (end) x_end = xs;
                        if (end && last) return write(t, xs);
                        // a segment's end is the next one's start, written there with its inputs
                        if (end) return true;
                        return on_output_grid(t) ? write(t, xs) : true;
                      });
        result.stats.steps += s.steps;
        result.stats.rhs_evals += s.rhs_evals;
        result.stats.jac_evals += s.jac_evals;
        result.stats.error_test_failures += s.error_test_failures;
        result.stats.nonlinear_failures += s.nonlinear_failures;
        result.stats.wall_seconds += s.wall_seconds;
        x = x_end;
        if (last) break;
      }
    }
  } catch (const IntegrationError& e) {
    bar.finish();
    if (output_failure || failure.empty()) throw;
    throw IntegrationError(fmt::format("{} ({})", e.reason, failure), e.t, e.x);
  }
  bar.finish();

  // Applied inputs or a controller do work: no invariant holds then.
  const bool driven = controller || (initial.w.size() && !initial.w.isZero(0.0));
  if (!driven) {
    const bench::InvariantSet inv = bench::invariants_of(model, initial.tau);
    // Generated code has only the energy and momentum the model's outputs ask
    // for; the invariants are then measured on the generic engine, at the same
    // states (a few evaluations per output row, after the run).
    const bool lacks = (inv.energy || inv.momentum) && dynamic_cast<GeneratedEngine*>(&engine) &&
                       !(model.outputs.energy && model.outputs.momentum);
    std::unique_ptr<GenericEngine> measure;
    if (lacks) {
      measure = std::make_unique<GenericEngine>(model);
      measure->set_parameters(engine.parameters());
    }
    const bench::Drifts d = bench::invariant_drifts(lacks ? *measure : engine, inv, sampled.traj);
    quality.energy_drift = d.energy;
    quality.H_drift = d.H;
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
    OdeProblem p2 = make_ode_problem(engine, initial.tau, &f2, options.use_jacobian,
                                     options.integrator.kind != IntegratorKind::rk4);
    try {
      integrate(p2, tight, initial.t, x0, options.t_end, options.dt_out, [&](double t, const VecX& x) {
        ref.add(t, x, !(t < options.t_end));
        return true;
      });
      const bench::ErrorMeasure e = bench::trajectory_error(model, sampled.traj, ref.traj);
      quality.error_estimate = e.error;
      quality.error_worst = fmt::format("{} at t = {:.6g}", e.worst, e.worst_t);
    } catch (const IntegrationError& e) {
      quality.error_worst = fmt::format("the tighter run failed: {}", e.reason);
    }
  }
  result.quality = quality;
  return result;
}

SimulationResult simulate_to_file(Engine& engine, const State& initial, const SimulationOptions& options,
                                  const std::string& path) {
  OutputFile out(path);  // the file appears only if the whole run succeeded
  const SimulationResult r = simulate(engine, initial, options, out.stream());
  out.commit();
  return r;
}

}  // namespace kanegen
