// Monte Carlo sweeps (docs/sweeps.md): runs of one model with dispersed
// runtime parameters and initial state, each run's draws a function of the
// base seed and the run index only (not of the scheduling), metrics per run,
// and the outputs: the table of runs, a summary, percentile envelopes. The
// scheduling (threads here; MPI ranks and shards in apps/kanegen/cmd_sweep)
// only decides who runs which index; the results are sorted by index, so
// they are byte-identical however the runs were spread.
#pragma once

#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "engine/engine.hpp"
#include "model/state_io.hpp"
#include "sim/simulate.hpp"
#include "model/sweep_spec.hpp"

namespace kanegen {

/// A sweep resolved against its model.
struct SweepPlan {
  SweepSpec spec;
  Model model;  ///< with the dispersed parameters among its runtime parameters
  struct Target {
    /// event_at / event_reaches: "events.<name>.at" / ".reaches" (model-format.md, Locks and events);
    /// input: "inputs.<name>", the named input's value for the whole run
    /// orbit: "orbit.<element>" (index 0-5: a, e, i, raan, argp, nu), "orbit.attitude_offset.x|y|z" (6-8: a
    /// rotation vector [rad] turning the root after the model's offset), "orbit.rate_offset.x|y|z" (9-11)
    enum class Kind { parameter, q, u, input, event_at, event_reaches, orbit } kind = Kind::parameter;
    int index = 0;  ///< into model.parameters, q, u, the inputs or model.events
    double nominal = 0.0;
  };
  /// Per dispersion the values one draw sets (its members, each parameter a name stands for).
  std::vector<std::vector<Target>> targets;
  /// Lower Cholesky factor of the correlation matrix of the normal dispersions (identity without
  /// `correlations:`), in the order of `normal_dispersions`.
  MatX correlation_factor;
  std::vector<int> normal_dispersions;
  std::vector<std::string> columns;  ///< a run's CSV columns
  /// Per metric its CSV column, or for "event.<name>.t" / "event.<name>.energy_lost" (an event's time, or
  /// the energy its latch took; NaN when it did not fire) -(2 e + 2) / -(2 e + 3), e the event's index.
  std::vector<int> metric_columns, envelope_columns;
};

/// Loads the model and checks the dispersions, metrics and envelopes against
/// it; throws InputError naming the sweep file's line and field.
SweepPlan plan_sweep(const SweepSpec& spec);

struct RunResult {
  long index = 0;
  std::string status = "ok";      ///< "ok", or "failed: <reason>"
  std::vector<double> values;     ///< the dispersed values (absolute), one per dispersion
  std::vector<double> metrics;    ///< NaN: failed, or a first_time condition that never held
  double wall_s = 0.0, integration_s = 0.0;
  std::vector<std::vector<double>> envelopes;  ///< per envelope column: its values at the output times
  bool ok() const { return status == "ok"; }
};

/// The dispersed values of run `index` (pure: the base seed and the index):
/// per dispersion the value of its first member.
std::vector<double> draw(const SweepPlan& plan, long index);

/// The control law of a closed-loop sweep, made afresh for each run (a law
/// may keep state of its own: integrators, filters, a mode) from the run's
/// model (plan.model) and index; an empty function or an empty Controller:
/// open loop.
using ControllerFactory = std::function<Controller(const Model& model, long index)>;

/// Run `index`'s initial state, parameter values and events, as run_one uses them.
struct RunSetup {
  std::vector<double> values;  ///< the table's dispersed values (draw(plan, index))
  State state;
  VecX parameters;
  std::vector<Event> events;
  SimulationOptions options;  ///< t_end, dt_out, integrator, events and the time limit of the sweep
  std::string failure;        ///< why the run cannot start (e.g. a dispersed orbit that is not elliptic)
};
RunSetup run_setup(const SweepPlan& plan, long index);

/// Runs one case on `engine` (made for plan.model); a failure is recorded in
/// the result, never thrown. With `csv`, the run's full time history.
RunResult run_one(Engine& engine, const SweepPlan& plan, long index, std::ostream* csv = nullptr,
                  const ControllerFactory& controller = {});

/// One result as one line of text and back (exact: 17 digits), for resuming
/// and for sending between processes.
std::string serialize(const RunResult& r);
RunResult deserialize(const std::string& line);

/// Runs `indices` on `threads` threads, each with its own engine from
/// `make_engine`, calling `done` (serialized, from one thread at a time) with
/// each result.
void run_on_threads(const SweepPlan& plan, const std::vector<long>& indices, int threads,
                    const std::function<std::unique_ptr<Engine>(const Model&)>& make_engine,
                    const std::function<void(RunResult&&)>& done, const ControllerFactory& controller = {});

/// Writes runs.csv (one row per run, by index: parameters, metrics, status),
/// timing.csv (wall and integration time per run: these alone depend on the
/// machine), summary.json, summary.md and envelope_<column>.csv into `dir`.
/// `results` must be sorted by index.
void write_sweep_outputs(const SweepPlan& plan, const std::vector<RunResult>& results, const std::string& dir);

/// The files a sweep reads: the sweep file, the model file and its modal
/// files (what none of its outputs may overwrite).
std::vector<std::string> sweep_input_files(const SweepPlan& plan);

/// Before any run (issue 34): the output directory `dir` of the sweep's
/// tables (check_output_directory_option, never one of the sweep's input
/// files nor one of the shard directories `merged`), named by `option` in a
/// refusal (an InputError, exit 2).
void check_sweep_output_directory(const std::string& option, const std::string& dir,
                                  const std::vector<std::string>& merged = {});

/// An 8-hex-digit identity of the sweep file's text: results of another
/// sweep are never resumed or merged with these.
std::string sweep_identity(const SweepPlan& plan);

}  // namespace kanegen
