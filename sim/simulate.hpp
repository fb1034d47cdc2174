// Time histories: integrates q_dot = W(q) u, M(q) u_dot = F(q, u, tau) with
// constant inputs tau from a state, and writes the CSV of interface.md.
#pragma once

#include <ostream>
#include <string>

#include "engine/engine.hpp"
#include "sim/integrators.hpp"
#include "model/state_io.hpp"

namespace kanegen {

struct SimulationOptions {
  double t_end = 10.0;
  double dt_out = 0.01;
  IntegratorOptions integrator;
  bool progress = false;  ///< progress bar on stderr
  bool use_jacobian = true;  ///< give implicit integrators the engine's exact Jacobian when it has one
};

struct SimulationResult {
  IntegratorStats stats;
  double max_quaternion_drift = 0.0;  ///< max | |quat| - 1 | seen at output times, before normalization
  long rows = 0;
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
/// Hx Hy Hz / <body>.fx .fy .fz .tx .ty .tz as the model's outputs ask.
std::vector<std::string> csv_columns(const Model& model);

/// Integrates from `initial` to options.t_end writing CSV rows to `csv`.
/// Throws IntegrationError (with time and state) on failure.
SimulationResult simulate(Engine& engine, const State& initial, const SimulationOptions& options, std::ostream& csv);

/// Simulates into `path` atomically: the file appears only if the whole run
/// succeeded (written to a temporary beside it, then renamed).
SimulationResult simulate_to_file(Engine& engine, const State& initial, const SimulationOptions& options,
                                  const std::string& path);

}  // namespace kanegen
