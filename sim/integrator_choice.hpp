// `--integrator auto`: the method picked from the scene, and why.
#pragma once

#include <cmath>
#include <string>

#include "engine/engine.hpp"
#include "model/state_io.hpp"
#include "sim/integrators.hpp"

namespace kanegen {

struct IntegratorChoice {
  IntegratorKind kind = IntegratorKind::dopri5;
  std::string reason;            ///< one sentence for the run's summary
  double spectral_radius = 0;    ///< max |lambda| of d x_dot / d x at the start [1/s]
  double fastest_decay = 0;      ///< -Re lambda of that eigenvalue [1/s] (0 if it does not decay)
  double explicit_steps = 0;     ///< steps an explicit method needs for stability alone over the horizon
  /// steps BDF needs to follow the fastest lightly damped oscillation (other
  /// than the dominant eigenvalue) at rtol over the horizon
  double resolved_steps_bdf = 0;
  /// The probe (a fast lightly damped oscillation): each candidate's cost over it in right-hand sides
  /// (deterministic), and how far apart they ended (relative to max(1, |x|)); NaN when no probe ran.
  double probe_interval = NAN, probe_rkf78_evals = NAN, probe_dirk_evals = NAN, probe_difference = NAN;
};

/// Picks the method for a run of `engine` from `initial` to t_end with output
/// interval dt_out at tolerance rtol, from the spectrum of the Jacobian of
/// x_dot = [q_dot; u_dot] at the initial state (the engine's exact Jacobian,
/// else central differences):
///  - stiff (the dominant eigenvalue decays within about a cycle, faster than
///    100 / dt_out, an explicit method would need more than 1e5 steps for
///    stability alone, and more than 3x the steps BDF needs anyway to follow
///    the scene's fastest lightly damped oscillation at rtol: otherwise the
///    run is accuracy-bound and explicit): cvode-bdf with the exact Jacobian;
///  - a fast, lightly damped oscillation that would cost an explicit method
///    more than 1e7 steps: cvode-bdf2 (A-stable; it damps that oscillation
///    numerically, which the reason says);
///  - a fast, lightly damped oscillation that would cost an explicit method
///    1e5 to 1e7 steps: a probe of rkf78 and arkode-dirk over 1 % of the
///    horizon (at least 100 of the oscillation's periods, at most the
///    horizon) and over twice that, projecting each one's right-hand sides
///    over the horizon; arkode-dirk when its projection is 1.5x below rkf78's
///    and ended within 1e4 rtol of rkf78 (the oscillation it damps is then not
///    excited enough to matter), else rkf78;
///  - otherwise non-stiff: rkf78, or dopri5 at rtol 1e-5 and looser.
IntegratorChoice choose_integrator(Engine& engine, const State& initial, double t_end, double dt_out, double rtol);

}  // namespace kanegen
