// Time integration of x' = f(t, x) with SUNDIALS (CVODE, ARKODE) or a
// fixed-step RK4. Knows nothing about multibody systems: simulate.hpp builds
// the OdeProblem from an engine.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace kanegen {

enum class IntegratorKind {
  cvode_bdf,    ///< CVODE, variable-order BDF, Newton with dense linear solver
  cvode_adams,  ///< CVODE, Adams-Moulton, fixed-point iteration (non-stiff)
  arkode_erk,   ///< ARKODE ERKStep, adaptive explicit Dormand-Prince 5(4)
  arkode_dirk,  ///< ARKODE ARKStep, fully implicit adaptive DIRK (order 4), Newton + dense
  rk4,          ///< classical fixed-step Runge-Kutta 4 (step = IntegratorOptions::h)
  cvode_bdf2,   ///< cvode_bdf with the order capped at 2 (A-stable): lightly damped stiff modes
  dopri5,       ///< Boost.Odeint Dormand-Prince 5(4) with dense output: non-stiff, low overhead per step
  rkf78,        ///< Boost.Odeint Runge-Kutta-Fehlberg 7(8): non-stiff, tight tolerances
  automatic,    ///< chosen from the scene by choose_integrator() (simulate.hpp)
};

/// CLI names: "auto", "cvode-bdf", "cvode-bdf2", "cvode-adams", "arkode-erk", "arkode-dirk", "rk4",
/// "dopri5", "rkf78".
std::string to_string(IntegratorKind kind);
/// Throws std::invalid_argument listing the valid names.
IntegratorKind integrator_from_string(const std::string& name);
std::vector<std::string> integrator_names();

struct OdeProblem {
  int n = 0;
  /// xdot = f(t, x). Return 0 on success, > 0 for a recoverable failure
  /// (the integrator retries with a smaller step), < 0 for an unrecoverable one.
  std::function<int(double t, const double* x, double* xdot)> rhs;
  /// Optional dense Jacobian df/dx, column-major n x n into J. Empty: the
  /// implicit methods use SUNDIALS' internal finite differences.
  std::function<int(double t, const double* x, const double* fx, double* J)> jacobian;
  /// Optional projection applied to an accepted state (e.g. quaternion
  /// normalization); used after each RK4 step and on every output state.
  std::function<void(double* x)> project;
  /// Optional event functions g_i(t, x), i < n_events (g has n_events
  /// entries): integrate() stops at the first time one of them goes from its
  /// sign at the start to the other sign or to zero, located to round-off in
  /// t on the step's interpolant (sim/event_location.hpp), and gives that
  /// time and state as its last output (IntegratorStats::event says which).
  int n_events = 0;
  std::function<void(double t, const double* x, double* g)> events;
};

struct IntegratorOptions {
  IntegratorKind kind = IntegratorKind::cvode_bdf;
  double rtol = 1e-8;
  double atol = 1e-10;
  double h = 1e-3;         ///< rk4 step; for adaptive methods: ignored
  long max_steps = 10'000'000;  ///< total steps before giving up
  int max_order = 0;       ///< cvode-bdf / cvode-adams: cap on the method order (0: CVODE's default, 5 / 12)
};

struct IntegratorStats {
  std::string integrator;
  long steps = 0;
  long rhs_evals = 0;      ///< every evaluation of f, incl. those for FD Jacobians
  long jac_evals = 0;      ///< Jacobian evaluations (user or finite-difference)
  long error_test_failures = 0;
  long nonlinear_failures = 0;
  double wall_seconds = 0.0;
  int event = -1;          ///< the event function that stopped the run (OdeProblem::events), -1 if none
  double t_event = 0.0;    ///< where it did
  /// "cvode-bdf: 1234 steps, 2345 rhs evals, 12 jac evals, 0.123 s"
  std::string summary() const;
};

/// A failure while integrating: step-size underflow, too many steps, an
/// unrecoverable RHS failure, ... with the time and state where it happened.
class IntegrationError : public std::runtime_error {
 public:
  /// `reason`: what happened, without the state; what() adds the state.
  IntegrationError(const std::string& reason, double t, Eigen::VectorXd x);
  double t;
  Eigen::VectorXd x;
  std::string reason;
};

/// Called at t0, t0 + dt_out, t0 + 2 dt_out, ..., and t_end (dense output /
/// interpolation for adaptive methods; RK4 steps land on output times).
/// Return false to stop early.
using OutputFn = std::function<bool(double t, const Eigen::VectorXd& x)>;

/// Integrates from (t0, x0) to t_end, or to the first event (OdeProblem::events).
/// Outputs: t0, the times grid_origin + k dt_out after t0 (grid_origin: t0
/// when not finite; a later segment of a run keeps its first segment's grid),
/// and t_end or the event's time. Throws IntegrationError on failure.
IntegratorStats integrate(const OdeProblem& problem, const IntegratorOptions& options, double t0,
                          const Eigen::VectorXd& x0, double t_end, double dt_out, const OutputFn& output,
                          double grid_origin = std::numeric_limits<double>::quiet_NaN());

}  // namespace kanegen
