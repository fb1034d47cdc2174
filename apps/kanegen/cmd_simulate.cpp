// kanegen simulate MODEL --t-end T -o OUT.csv: integrate and write the time history.
#include <fmt/format.h>

#include "apps/common/simulation_cli.hpp"
#include "apps/kanegen/cli_common.hpp"
#include "engine/handover_engine.hpp"
#include "model/model_files.hpp"
#include "model/output_file.hpp"

namespace kanegen::cli {

namespace simulate_command {

struct Options {
  std::string model, state, engine = "auto", events;
  bool native = false;
  SimulationCli sim;
  CLI::Option* events_option = nullptr;  ///< to tell --events "" from no --events
};

int run(const Options& o) {
  const Model model = load_checked(o.model);
  const State state = state_for(model, o.state);
  const SimulationOptions opt = simulation_options(o.sim, state);
  std::vector<OutputOption> outputs{{"-o", o.sim.output}};
  if (o.events_option->count() > 0) outputs.push_back({"--events", o.events});
  check_output_options(outputs, input_files(model, o.state));  // before any work: nothing is written on a refusal
  // explicit methods (and auto's choice, from central differences when no
  // Jacobian is compiled) need no derivatives; the implicit ones use the exact Jacobian
  const IntegratorKind k = opt.integrator.kind;
  const bool explicit_method = k == IntegratorKind::automatic || k == IntegratorKind::rkf78 ||
                               k == IntegratorKind::dopri5 || k == IntegratorKind::rk4 ||
                               k == IntegratorKind::arkode_erk;
  auto engine = make_engine(model, o.engine, o.native, /*derivatives=*/!explicit_method);
  auto* handover = dynamic_cast<HandoverEngine*>(engine.get());
  if (handover) handover->set_horizon(state.t, opt.t_end);
  int status = 0;
  try {
    const SimulationResult r = simulate_to_file(*engine, state, opt, o.sim.output);
    const std::string engine_label = handover && handover->handed_over()
                                         ? fmt::format("generic engine, then generated from t = {:.6g} s",
                                                       handover->handover_time())
                                         : engine->name() + " engine";
    fmt::print(stderr, "{} [{}], {} rows to {}, max quaternion drift {:.2e}\n{}", r.stats.summary(), engine_label,
               r.rows, o.sim.output, r.max_quaternion_drift, describe_quality(r.quality));
    if (!r.events.empty())
      fmt::print(stderr, "events ({} fired, {} segments): {}\n", r.events.size(), r.segments, events_summary(r.events));
    else if (!model.events.empty())
      fmt::print(stderr, "events: none fired\n");
    if (!o.events.empty()) {
      OutputFile out(o.events);
      write_events_csv(r.events, out.stream());
      out.commit();
    }
  } catch (const IntegrationError& e) {
    fmt::print(stderr, "kanegen simulate: {}\nno output written\n", describe_failure(model, e));
    status = kExitFailure;
  }
  if (handover) {
    if (!handover->build_done())
      fmt::print(stderr,
                 "kanegen: run done at {:.2f} s; the generated code of {} goes on building in the background "
                 "(kanegen compile, nice 10), cached for the next run\n",
                 seconds_since_start(), model.name);
    else if (!handover->error().empty())
      fmt::print(stderr, "kanegen: warning: the generated code of {} did not build ({}); the generic engine ran\n",
                 model.name, handover->error());
  }
  return status;
}

}  // namespace simulate_command

Subcommand add_simulate(CLI::App& app) {
  auto o = std::make_shared<simulate_command::Options>();
  CLI::App* c = app.add_subcommand("simulate", "integrate the equations of motion and write a CSV time history");
  add_model_option(c, o->model);
  add_simulation_options(c, o->sim, true);
  c->get_option("-o")->required();
  c->add_option("--state", o->state, "initial STATE.json (default: the model's initial state)")
      ->check(CLI::ExistingFile);
  o->events_option = c->add_option("--events", o->events,
                "also write the events that fired as CSV (t, name, action, bodies, energy_lost; interface.md)");
  add_engine_option(c, o->engine, o->native, /*with_auto=*/true);
  return {c, [o] { return simulate_command::run(*o); }};
}

}  // namespace kanegen::cli
