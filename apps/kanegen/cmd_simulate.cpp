// kanegen simulate MODEL --t-end T -o OUT.csv: integrate and write the time history.
#include <fmt/format.h>

#include "apps/kanegen/cli_common.hpp"
#include "model/diagnostics.hpp"
#include "model/output_file.hpp"
#include "sim/integrators.hpp"
#include "sim/simulate.hpp"

namespace kanegen::cli {

namespace {

struct Options {
  std::string model, state, engine = "generated", output, integrator = "cvode-bdf";
  double t_end = 10.0, rtol = 1e-8, atol = 1e-10, dt_out = 0.01, h = 1e-3;
  bool no_progress = false;
};

int run(const Options& o) {
  check_output_path(o.output);
  const Model model = load_checked(o.model);
  const State state = state_for(model, o.state);
  SimulationOptions opt;
  opt.t_end = o.t_end;
  opt.dt_out = o.dt_out;
  try {
    opt.integrator.kind = integrator_from_string(o.integrator);
  } catch (const std::invalid_argument& e) {
    throw InputError(Diagnostic{"--integrator", 0, "", e.what()});
  }
  opt.integrator.rtol = o.rtol;
  opt.integrator.atol = o.atol;
  opt.integrator.h = o.h;
  opt.progress = !o.no_progress;
  if (!(o.t_end > state.t)) throw InputError(Diagnostic{"--t-end", 0, "", "must be after the initial time"});
  if (!(o.dt_out > 0)) throw InputError(Diagnostic{"--dt-out", 0, "", "must be positive"});
  auto engine = make_engine(model, o.engine);
  try {
    const SimulationResult r = simulate_to_file(*engine, state, opt, o.output);
    fmt::print(stderr, "{} [{} engine], {} rows to {}, max quaternion drift {:.2e}\n", r.stats.summary(),
               engine->name(), r.rows, o.output, r.max_quaternion_drift);
  } catch (const IntegrationError& e) {
    std::string where;
    const int n = std::min<int>(static_cast<int>(e.x.size()), model.nq + model.nu);
    for (int i = 0; i < n; ++i)
      where += i < model.nq ? fmt::format("\n  q {} = {:.17g}", model.q_names[i], e.x(i))
                            : fmt::format("\n  u {} = {:.17g}", model.u_names[i - model.nq], e.x(i));
    fmt::print(stderr, "kanegen simulate: integration failed at t = {:.17g}: {}\nstate there:{}\nno output written\n",
               e.t, e.what(), where);
    return kExitFailure;
  }
  return 0;
}

}  // namespace

Subcommand add_simulate(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* c = app.add_subcommand("simulate", "integrate the equations of motion and write a CSV time history");
  add_model_option(c, o->model);
  c->add_option("--t-end", o->t_end, "final time [s]")->required();
  c->add_option("-o,--output", o->output, "output CSV file")->required();
  c->add_option("--state", o->state, "initial STATE.json (default: the model's initial state)")
      ->check(CLI::ExistingFile);
  add_engine_option(c, o->engine);
  c->add_option("--integrator", o->integrator,
                "cvode-bdf | cvode-bdf2 (BDF capped at order 2, for lightly damped stiff modes) | cvode-adams | "
                "arkode-erk | arkode-dirk | rk4")
      ->capture_default_str();
  c->add_option("--rtol", o->rtol, "relative tolerance (adaptive integrators)")->capture_default_str();
  c->add_option("--atol", o->atol, "absolute tolerance (adaptive integrators)")->capture_default_str();
  c->add_option("--dt-out", o->dt_out, "output interval [s]")->capture_default_str();
  c->add_option("--h", o->h, "fixed step of rk4 [s]")->capture_default_str();
  c->add_flag("--no-progress", o->no_progress, "no progress bar on stderr");
  return {c, [o] { return run(*o); }};
}

}  // namespace kanegen::cli
