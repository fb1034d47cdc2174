// The simulation options of the command line, shared by `kanegen simulate`
// and every ahead-of-time simulator (apps/aot/aot_simulator.hpp): declared
// once, and checked up front, each against its domain, so that a bad value
// is refused (exit 2) naming the option and the value the user gave, before
// anything is computed or written. Header-only (the simulators include it).
#pragma once

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cmath>
#include <string>

#include "model/diagnostics.hpp"
#include "model/output_file.hpp"
#include "model/state_io.hpp"
#include "sim/integrators.hpp"
#include "sim/simulate.hpp"

namespace kanegen::cli {

struct SimulationCli {
  std::string output, integrator = "auto";
  double t_end = 10.0, rtol = 1e-10, atol = 1e-12, dt_out = 0.01, h = 1e-3;
  long max_steps = 100'000'000;
  bool no_progress = false;
  bool estimate_error = false;
};

/// Largest number of CSV rows a run may write (about 2 GB for ten columns):
/// beyond it the run is refused up front.
inline constexpr double kMaxOutputRows = 1e7;
/// Largest number of fixed RK4 steps a run may take.
inline constexpr double kMaxFixedSteps = 1e10;

/// Adds --t-end (required when `t_end_required`), -o, --integrator, --rtol,
/// --atol, --dt-out, --h, --no-progress.
inline void add_simulation_options(CLI::App* c, SimulationCli& o, bool t_end_required) {
  auto* t = c->add_option("--t-end", o.t_end, "final time [s]");
  if (t_end_required) t->required();
  else t->capture_default_str();
  c->add_option("-o,--output", o.output, "output CSV file (interface.md)");
  c->add_option("--integrator", o.integrator,
                "auto (picked from the Jacobian's spectrum at the start; the summary says what and why) | dopri5 | "
                "rkf78 | cvode-bdf | cvode-bdf2 (BDF capped at order 2, for lightly damped stiff modes) | "
                "cvode-adams | arkode-erk | arkode-dirk | rk4")
      ->capture_default_str();
  c->add_option("--rtol", o.rtol, "relative tolerance (adaptive integrators), in (0, 1)")->capture_default_str();
  c->add_option("--atol", o.atol, "absolute tolerance (adaptive integrators), > 0")->capture_default_str();
  c->add_option("--dt-out", o.dt_out, "output interval [s], > 0")->capture_default_str();
  c->add_option("--h", o.h, "fixed step of rk4 [s], > 0")->capture_default_str();
  c->add_option("--max-steps", o.max_steps, "steps allowed in all before the run fails, >= 1")->capture_default_str();
  c->add_flag("--no-progress", o.no_progress, "no progress bar on stderr");
  c->add_flag("--estimate-error", o.estimate_error,
              "run again at tolerances 100x tighter and report the difference as the error estimate");
}

/// The SimulationOptions of `o` for a run from `initial`; throws InputError
/// (one diagnostic per bad option, an unwritable -o among them).
inline SimulationOptions simulation_options(const SimulationCli& o, const State& initial) {
  std::vector<Diagnostic> faults;
  auto fault = [&](const char* option, const std::string& what) { faults.push_back(Diagnostic{option, 0, "", what}); };
  SimulationOptions opt;
  try {
    opt.integrator.kind = integrator_from_string(o.integrator);
  } catch (const std::invalid_argument& e) {
    fault("--integrator", e.what());
  }
  const double t0 = initial.t;
  if (!std::isfinite(o.t_end))
    fault("--t-end", fmt::format("got {}; expected a finite time after the initial time {}", o.t_end, t0));
  else if (!(o.t_end > t0))
    fault("--t-end", fmt::format("got {}; expected a time after the initial time {}", o.t_end, t0));
  if (!(std::isfinite(o.dt_out) && o.dt_out > 0))
    fault("--dt-out", fmt::format("got {}; expected a positive, finite output interval", o.dt_out));
  if (!(std::isfinite(o.rtol) && o.rtol > 0 && o.rtol < 1))
    fault("--rtol", fmt::format("got {}; expected a relative tolerance in (0, 1)", o.rtol));
  if (!(std::isfinite(o.atol) && o.atol > 0))
    fault("--atol", fmt::format("got {}; expected a positive, finite absolute tolerance", o.atol));
  if (!(std::isfinite(o.h) && o.h > 0)) fault("--h", fmt::format("got {}; expected a positive, finite step", o.h));
  if (o.max_steps < 1) fault("--max-steps", fmt::format("got {}; expected at least 1", o.max_steps));
  if (faults.empty()) {
    const double rows = std::floor((o.t_end - t0) / o.dt_out) + 2;
    if (!(rows <= kMaxOutputRows))
      fault("--dt-out", fmt::format("the run from t = {} to {} every {} s would write {:.3g} rows (more than {:.0e}); "
                                    "expected a larger --dt-out or a shorter --t-end",
                                    t0, o.t_end, o.dt_out, rows, kMaxOutputRows));
    const double steps = (o.t_end - t0) / o.h;
    if (opt.integrator.kind == IntegratorKind::rk4 && !(steps <= kMaxFixedSteps))
      fault("--h", fmt::format("rk4 would take {:.3g} steps of {} s (more than {:.0e}); expected a larger step",
                               steps, o.h, kMaxFixedSteps));
  }
  if (o.output.empty()) fault("-o", "cannot write '': empty output path; expected an output CSV file");
  if (!faults.empty()) throw InputError(faults);
  check_output_option("-o", o.output);
  opt.t_end = o.t_end;
  opt.dt_out = o.dt_out;
  opt.integrator.rtol = o.rtol;
  opt.integrator.atol = o.atol;
  opt.integrator.h = o.h;
  opt.integrator.max_steps = o.max_steps;
  opt.progress = !o.no_progress;
  opt.estimate_error = o.estimate_error;
  return opt;
}

/// The lines a run prints after its statistics: the method `auto` picked and
/// why, the invariant drift and the error estimate.
inline std::string describe_quality(const RunQuality& q) {
  std::string s;
  if (!q.integrator_choice.empty()) s += "integrator auto: " + q.integrator_choice + "\n";
  s += "accuracy: " + q.summary() + "\n";
  for (const std::string& w : q.warnings) s += "warning: " + w + "\n";
  return s;
}

/// "integration failed at t = ...: reason" and the state there, by name.
inline std::string describe_failure(const Model& model, const IntegrationError& e) {
  std::string s = fmt::format("integration failed at t = {:.17g}: {}\nstate there:", e.t, e.reason);
  const int n = std::min<int>(static_cast<int>(e.x.size()), model.nq + model.nu);
  for (int i = 0; i < n; ++i)
    s += i < model.nq ? fmt::format("\n  q {} = {:.17g}", model.q_names[i], e.x(i))
                      : fmt::format("\n  u {} = {:.17g}", model.u_names[i - model.nq], e.x(i));
  return s;
}

}  // namespace kanegen::cli
