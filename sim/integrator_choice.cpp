#include "sim/integrator_choice.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <complex>

#include "sim/simulate.hpp"

namespace kanegen {

namespace {

/// Explicit Runge-Kutta methods of order 5 are stable for |h lambda| up to
/// about 3.3 (Dormand-Prince 5(4): 3.3 on the negative real axis).
constexpr double kExplicitStabilityRadius = 3.3;
constexpr double kStiffSteps = 1e5;        ///< stability-limited explicit steps above which BDF pays off
constexpr double kOscillationSteps = 1e7;  ///< ... above which even a resolved oscillation is left to BDF2
constexpr int kMaxDenseEigen = 400;
/// The probe of rkf78 against arkode-dirk (choose_integrator): the share of
/// the horizon it runs, the speed-up DIRK must show, and how close to rkf78
/// it must end (in units of rtol, relative to max(1, |x|)).
constexpr double kProbeShare = 0.01;
constexpr double kProbeSpeedup = 1.5;
constexpr double kProbeAgreement = 1e4;
/// rkf78 below this rtol, dopri5 above: on explorer1_rigid over 3000 s rkf78
/// takes the same time as dopri5 at rtol 1e-6 with a 90x smaller error, and
/// half the time at 1e-10 with a 200x smaller error (docs/speed.md).
constexpr double kHighOrderBelowRtol = 1e-5;        ///< larger systems: power iteration for the dominant eigenvalue

/// d x_dot / d x at x0 (n x n): the problem's exact Jacobian, else central differences.
MatX jacobian_at(const OdeProblem& p, double t0, const VecX& x0) {
  const int n = p.n;
  MatX J(n, n);
  VecX f0(n);
  if (p.rhs(t0, x0.data(), f0.data()) != 0) throw std::runtime_error("the right-hand side fails at the start");
  if (p.jacobian && p.jacobian(t0, x0.data(), f0.data(), J.data()) == 0 && J.allFinite()) return J;
  VecX xp = x0, fp(n), fm(n);
  for (int k = 0; k < n; ++k) {
    const double h = 1e-6 * std::max(1.0, std::abs(x0(k)));
    xp(k) = x0(k) + h;
    const int a = p.rhs(t0, xp.data(), fp.data());
    xp(k) = x0(k) - h;
    const int b = p.rhs(t0, xp.data(), fm.data());
    xp(k) = x0(k);
    if (a != 0 || b != 0) throw std::runtime_error("the right-hand side fails next to the start");
    J.col(k) = (fp - fm) / (2 * h);
  }
  return J;
}

/// Steps per period an explicit Runge-Kutta method of order p takes to follow
/// an oscillation at relative tolerance rtol (the local error of a step h on
/// sin(w t) is ~ (w h)^(p+1): w h ~ rtol^(1/(p+1)), 2 pi / (w h) steps per
/// period); BDF's order is at most 5, so it needs more of them.
double steps_per_period(double rtol, int order) { return 2.0 * M_PI * std::pow(rtol, -1.0 / (order + 1)); }

/// One candidate over [t0, t0 + 2 span], in one run: its cost in right-hand
/// sides at t0 + span and at the end (an exact Jacobian counted as
/// kJacobianEvals of them; a run's choice must not depend on the machine's
/// load, so no wall time) and the end state (empty if it failed).
constexpr double kJacobianEvals = 10.0;
struct ProbeRun {
  double cost_half = INFINITY;  ///< at t0 + span
  double cost = INFINITY;       ///< at t0 + 2 span
  VecX x_end;
};
ProbeRun probe_run(const OdeProblem& p, IntegratorKind kind, double rtol, double t0, const VecX& x0, double span) {
  IntegratorOptions o;
  o.kind = kind;
  o.rtol = rtol;
  o.atol = rtol / 100;
  o.max_steps = 1'000'000;
  double evals = 0;  // the right-hand sides and Jacobians the integrator asks for, counted as they come
  OdeProblem counted = p;
  counted.rhs = [&](double t, const double* x, double* xd) {
    evals += 1.0;
    return p.rhs(t, x, xd);
  };
  if (p.jacobian)
    counted.jacobian = [&](double t, const double* x, const double* fx, double* J) {
      evals += kJacobianEvals;
      return p.jacobian(t, x, fx, J);
    };
  ProbeRun r;
  try {
    integrate(counted, o, t0, x0, t0 + 2 * span, span, [&](double t, const VecX& x) {
      if (t < t0 + 1.5 * span && t > t0 + 0.5 * span) r.cost_half = evals;
      r.x_end = x;
      return true;
    });
    r.cost = evals;
  } catch (const std::exception&) {
    r.x_end.resize(0);
    r.cost = r.cost_half = INFINITY;
  }
  return r;
}

struct Spectrum {
  std::complex<double> dominant = 0.0;  ///< the eigenvalue of largest modulus
  /// The fastest lightly damped oscillation other than the dominant
  /// eigenvalue (|Im| > |Re|): the motion an accurate run has to resolve
  /// whatever the method (a spin, a nutation, a whip near resonance); 0 if none or unknown.
  double oscillation = 0.0;
};

/// The eigenvalue of largest modulus, and the fastest resolved oscillation.
Spectrum spectrum_of(const MatX& J) {
  Spectrum s;
  if (J.rows() == 0) return s;  // no degree of freedom
  if (J.rows() <= kMaxDenseEigen) {
    const Eigen::EigenSolver<MatX> es(J, false);
    if (es.info() == Eigen::Success) {
      const auto& ev = es.eigenvalues();
      Eigen::Index k = 0;
      ev.cwiseAbs().maxCoeff(&k);
      s.dominant = ev(k);
      for (Eigen::Index i = 0; i < ev.size(); ++i)
        if (std::abs(ev(i)) < 0.999 * std::abs(s.dominant) && std::abs(ev(i).imag()) > std::abs(ev(i).real()))
          s.oscillation = std::max(s.oscillation, std::abs(ev(i).imag()));
      return s;
    }
  }
  // Power iteration on J^2 (a complex pair of equal modulus does not converge
  // on J itself): gives |lambda|^2; the decay rate is then not resolved.
  VecX v = VecX::Ones(J.rows()) / std::sqrt(static_cast<double>(J.rows()));
  double r2 = 0;
  for (int it = 0; it < 100; ++it) {
    VecX w = J * (J * v);
    r2 = w.norm();
    if (!(r2 > 0)) break;
    v = w / r2;
  }
  s.dominant = {0.0, std::sqrt(r2)};
  return s;
}

}  // namespace

IntegratorChoice choose_integrator(Engine& engine, const State& initial, double t_end, double dt_out, double rtol) {
  const Model& model = engine.model();
  IntegratorChoice c;
  std::string failure;
  const OdeProblem p = make_ode_problem(engine, initial.tau, &failure, true, true);
  VecX x0(model.nq + model.nu);
  x0 << initial.q, initial.u;
  const double horizon = t_end - initial.t;
  const Spectrum sp = spectrum_of(jacobian_at(p, initial.t, x0));
  const std::complex<double> lambda = sp.dominant;
  c.spectral_radius = std::abs(lambda);
  c.fastest_decay = std::max(0.0, -lambda.real());
  c.explicit_steps = c.spectral_radius * horizon / kExplicitStabilityRadius;
  const bool decays_within_a_cycle = lambda.real() < 0 && std::abs(lambda.imag()) <= 2.0 * -lambda.real();
  const std::string spectrum = fmt::format("dominant eigenvalue {:.3g}{:+.3g}i of the Jacobian at the start",
                                           lambda.real(), lambda.imag());
  // Stiffness is stability against accuracy: BDF pays off only when the steps
  // an explicit method needs for stability exceed, by the cost of an implicit
  // step (about 3x), those BDF needs anyway to follow the oscillations that
  // an accurate run resolves (a spinning spacecraft's nutation, a whip near
  // resonance): then an explicit method is held back by accuracy, not stability.
  c.resolved_steps_bdf = horizon * sp.oscillation / (2.0 * M_PI) * steps_per_period(rtol, 5);
  const bool accuracy_bound = c.explicit_steps < 3.0 * c.resolved_steps_bdf;
  if (decays_within_a_cycle && c.fastest_decay * dt_out > 100 && c.explicit_steps > kStiffSteps && !accuracy_bound) {
    c.kind = IntegratorKind::cvode_bdf;
    c.reason = fmt::format("stiff: {} (a mode that dies out within {:.2g} s, far inside the output interval {} s) "
                           "would hold an explicit method to {:.2g} steps over the horizon: cvode-bdf with the "
                           "exact Jacobian",
                           spectrum, 1.0 / c.fastest_decay, dt_out, c.explicit_steps);
  } else if (!decays_within_a_cycle && c.explicit_steps > kStiffSteps && c.explicit_steps <= kOscillationSteps && std::abs(lambda.imag()) > 0 &&
             [&] {
               // a probe: whether an L-stable DIRK, which damps the fast oscillation, runs the
               // scene faster and ends where rkf78 does (the oscillation then hardly excited)
               const double period = 2.0 * M_PI / std::abs(lambda.imag());
               c.probe_interval = std::min(horizon, std::max(kProbeShare * horizon, 100.0 * period));
               // each candidate over the interval and over twice it: the difference is its cost per
               // interval once started (an implicit method's start-up is many small steps), which
               // projects its cost over the horizon
               // (one run over twice the interval, its cost read at the interval's end)
               auto projected = [&](IntegratorKind k, ProbeRun& run) {
                 run = probe_run(p, k, rtol, initial.t, x0, c.probe_interval);
                 return run.cost_half + std::max(0.0, run.cost - run.cost_half) * (horizon / c.probe_interval - 1.0);
               };
               ProbeRun rk, dirk;
               c.probe_rkf78_evals = projected(IntegratorKind::rkf78, rk);
               c.probe_dirk_evals = projected(IntegratorKind::arkode_dirk, dirk);
               if (rk.x_end.size() != x0.size() || dirk.x_end.size() != x0.size()) return false;
               c.probe_difference = (dirk.x_end - rk.x_end).cwiseAbs().maxCoeff() /
                                    std::max(1.0, rk.x_end.cwiseAbs().maxCoeff());
               return c.probe_dirk_evals * kProbeSpeedup < c.probe_rkf78_evals &&
                      c.probe_difference <= kProbeAgreement * rtol;
             }()) {
    c.kind = IntegratorKind::arkode_dirk;
    c.reason = fmt::format("{} is a fast, lightly damped oscillation that would cost an explicit method {:.2g} "
                           "steps; a probe over {:.3g} s projects arkode-dirk to {:.3g} right-hand sides over the "
                           "horizon against rkf78's {:.3g}, the two ending "
                           "{:.2g} apart (relative): arkode-dirk (L-stable, order 4; it damps that oscillation, "
                           "which the probe found hardly excited)",
                           spectrum, c.explicit_steps, c.probe_interval, c.probe_dirk_evals, c.probe_rkf78_evals,
                           c.probe_difference);
  } else if (c.explicit_steps > kOscillationSteps) {
    c.kind = IntegratorKind::cvode_bdf2;
    c.reason = fmt::format("{} is a fast, lightly damped oscillation that would cost an explicit method {:.2g} "
                           "steps: cvode-bdf2 (A-stable; it damps that oscillation numerically: if it matters, "
                           "run dopri5 and compare)",
                           spectrum, c.explicit_steps);
  } else {
    c.kind = rtol < kHighOrderBelowRtol ? IntegratorKind::rkf78 : IntegratorKind::dopri5;
    const std::string probed =
        std::isnan(c.probe_interval)
            ? ""
            : fmt::format("; a probe over {:.3g} s found arkode-dirk no better (right-hand sides projected over "
                          "the horizon: rkf78 {:.3g}, arkode-dirk {:.3g}; ending {:.2g} apart)",
                          c.probe_interval, c.probe_rkf78_evals, c.probe_dirk_evals, c.probe_difference);
    const std::string why =
        decays_within_a_cycle && c.explicit_steps > kStiffSteps && accuracy_bound
            ? fmt::format("accuracy-bound: {} would allow an explicit method {:.2g} steps, but the oscillation at "
                          "{:.3g} rad/s needs ~{:.2g} steps of BDF (order <= 5) to follow at this rtol",
                          spectrum, c.explicit_steps, sp.oscillation, c.resolved_steps_bdf)
            : fmt::format("non-stiff: {} bounds an explicit method's steps by {:.2g} over the horizon", spectrum,
                          c.explicit_steps);
    c.reason = fmt::format("{}{}: {} (explicit, {})", why, probed, to_string(c.kind),
                           c.kind == IntegratorKind::rkf78 ? "order 7(8), for rtol below 1e-5"
                                                           : "order 5(4), for loose tolerances");
  }
  return c;
}

}  // namespace kanegen
