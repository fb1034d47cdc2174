// Time histories: integrates q_dot = W(q) u, M(q) u_dot = F(q, u, tau, w) with
// constant tau from a state and the named inputs w constant or set by a
// controller, and writes the CSV of interface.md (plus the named inputs and
// outputs, docs/gnc.md).
#pragma once

#include <cmath>
#include <optional>
#include <ostream>
#include <string>

#include "engine/engine.hpp"
#include "sim/controller.hpp"
#include "sim/event_run.hpp"
#include "sim/integrators.hpp"
#include "sim/row_sink.hpp"
#include "model/state_io.hpp"

namespace kanegen {

struct SimulationOptions {
  double t_end = 10.0;
  double dt_out = 0.01;
  IntegratorOptions integrator;
  bool progress = false;  ///< progress bar on stderr
  bool use_jacobian = true;  ///< give implicit integrators the engine's exact Jacobian when it has one
  /// Also run at rtol/100, atol/100 (same method) and report the difference
  /// of the two runs at the output times as the error estimate.
  bool estimate_error = false;
  /// A control law setting the named inputs (sim/controller.hpp); without
  /// one the inputs stay at State::w for the whole run.
  Controller controller;
  /// Seconds of wall time the integration may take (0: no limit); past it the run fails (IntegrationError).
  double wall_time_limit = 0.0;
  /// The events of the run instead of the model's (same entries; a sweep disperses their times and values).
  std::optional<std::vector<Event>> events;
};

/// How far a run can be trusted, for its summary.
struct RunQuality {
  std::string integrator_choice;   ///< why `auto` picked the method ("" if it was named)
  /// Relative drift of the invariants that hold for the scene (NaN otherwise), over the output times
  /// (docs/decisions.md, "Reports in orbit"): max |E - E0| against max(T + |V|) and max |H - H0| against
  /// max(|H0|, sqrt(2 T_max I_max)) (a zero H is no scale); in a central field both against the motion
  /// about the centre of mass (T_c, H_c), the orbit's share apart. H_z alone with J2 (H_z).
  double energy_drift = NAN, H_drift = NAN;
  /// The same in their units, the scales and the totals (with the orbit's share), from the worst segment.
  double energy_drift_J = NAN, energy_scale_J = NAN, energy_total_J = NAN;
  double H_drift_Nms = NAN, H_scale_Nms = NAN, H_total_Nms = NAN;
  bool about_com = false;  ///< the scales are the motion about the centre of mass (a central field)
  /// The integrator's accepted steps: with about_com, a drift of the order of sqrt(steps) ulps of the
  /// total with the orbit is the orbit's round-off (its digits carried step by step), which the summary
  /// says rather than reading it as an error of the motion about the centre of mass.
  long steps = 0;
  bool H_z = false;        ///< the momentum drift is H_z's (central gravity with J2)
  /// When prescribed motion alone does work (Invariants::energy_with_drivers): the balance
  /// max |E - E0 - W_drivers| / max(T + |V|) over the output times (sim/driver_work.hpp); NaN otherwise.
  double energy_balance = NAN;
  double energy_balance_quadrature = NAN;  ///< the part of it the quadrature of W can explain
  /// With SimulationOptions::estimate_error: the error of the run against the
  /// tighter one, measured as `kanegen bench` measures it (relative, worst
  /// component over the output times), and where it is largest.
  double error_estimate = NAN;
  std::string error_worst;
  /// Why an invariant does not hold here (model/invariants.hpp): "energy not conserved: dampers on 4 joints".
  std::string invariants_note;
  /// What the run did that the model does not describe well: a flexible body deflected beyond the
  /// linear range (sim/modal_range.hpp), one line each.
  std::vector<std::string> warnings;
  /// "energy drift 3.1e-10, |H| drift 2.2e-12, estimated error 4.5e-9 (u link3.angle at t = 9.5)"
  std::string summary() const;
};

struct SimulationResult {
  IntegratorStats stats;
  double max_quaternion_drift = 0.0;  ///< max | |quat| - 1 | seen at output times, before normalization
  long rows = 0;
  RunQuality quality;
  /// The events that fired (sim/event_run.hpp), in order, and the segments integrated between them.
  std::vector<FiredEvent> events;
  long segments = 0;
};

/// The ODE x = [q; u] of an engine, for the integrators. The right-hand side
/// normalizes quaternions before use; a singular M or a non-finite state
/// makes it fail (unrecoverably) with the reason stored in `failure`.
/// With `stabilize_quaternions`, q_dot of each free joint's quaternion gets
/// + lambda (1 - |q|^2) q (zero on the unit sphere; for adaptive methods: RK4
/// renormalizes after each step instead).
OdeProblem make_ode_problem(Engine& engine, const VecX& tau, std::string* failure, bool use_jacobian = true,
                            bool stabilize_quaternions = true);

/// Column names of the CSV: t, q names, the prescribed coordinates (named as
/// the joint coordinate would be, e.g. hub.angle), u names, then T V /
/// Hx Hy Hz / <body>.fx .fy .fz .tx .ty .tz as the model's outputs ask, then
/// the named inputs and the named outputs.
std::vector<std::string> csv_columns(const Model& model);

/// Integrates from `initial` to options.t_end giving the rows (the columns of
/// csv_columns) to `sink`: every row is checked before the sink sees it.
/// Throws IntegrationError (with time and state) on failure.
SimulationResult simulate(Engine& engine, const State& initial, const SimulationOptions& options, RowSink& sink);

/// The same, the rows written as CSV (interface.md) to `csv`.
SimulationResult simulate(Engine& engine, const State& initial, const SimulationOptions& options, std::ostream& csv);

/// Simulates into `path` atomically: the file appears only if the whole run
/// succeeded (written to a temporary beside it, then renamed).
SimulationResult simulate_to_file(Engine& engine, const State& initial, const SimulationOptions& options,
                                  const std::string& path);

}  // namespace kanegen
