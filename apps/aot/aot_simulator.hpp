// main() of an ahead-of-time simulator built by kanegen_add_model()
// (cmake/KanegenAddModel.cmake; called from the generated entry file built
// with -DKANEGEN_AOT_MAIN, templates/entry.cpp.in): the model's
// generated code is linked in (no generator, no compiler, no cache at run
// time); the model file is still read at start for names, the initial state and
// the outputs, and must be the one the code was generated from (hash-checked).
// Header-only so that the runtime library does not depend on CLI11; only the
// simulator's main translation unit includes it.
#pragma once

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <string>

#include "apps/common/command_line_arguments.hpp"
#include "apps/common/simulation_cli.hpp"
#include "apps/common/sweep_cli.hpp"
#include "engine/generated_api.h"
#include "engine/generated_engine.hpp"
#include "engine/model_checks.hpp"
#include "model/diagnostics.hpp"
#include "model/model_files.hpp"
#include "engine/load_model.hpp"
#include "model/output_file.hpp"
#include "model/state_io.hpp"
#include "sim/eval_report.hpp"
#include "sim/integrators.hpp"
#include "sim/simulate.hpp"

#ifdef KANEGEN_HAS_CONTROLLER
#include "sim/controller.hpp"
/// Defined by the CONTROLLER file of kanegen_add_model() (docs/gnc.md).
kanegen::Controller kanegen_controller(const kanegen::Model& model);
#endif

namespace kanegen {

/// Exit status as the kanegen CLI: 0 success, 2 refused input, 1 failure while running.
/// f()'s exit status, or the contract's for what it throws: 2 for a refused input or output, 1 for a failure.
template <class F>
int exit_status_of(const std::string& program, F&& f) {
  try {
    return f();
  } catch (const InputError& e) {
    for (const Diagnostic& d : e.diagnostics()) fmt::print(stderr, "{}\n", d.str());
    return 2;
  } catch (const OutputRefused& e) {
    fmt::print(stderr, "{}: cannot write output {}\n", program, e.what());
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "{}: {}\n", program, e.what());
    return 1;
  }
}

inline int aot_simulator_main(int argc, char** argv, const KanegenGeneratedApi* api, const std::string& model_path,
                              const std::string& program) {
  std::string model_file = model_path, state_path;
  cli::SimulationCli sim;
  bool eval = false;

  CLI::App app{fmt::format("{}: simulator of model '{}' with its generated equations of motion compiled in", program,
                           api && api->model_name ? api->model_name : "?")};
  cli::add_simulation_options(&app, sim, false);
  app.add_option("--state", state_path, "initial STATE.json (default: the model's initial state)")
      ->check(CLI::ExistingFile);
  app.add_option("--model", model_file, "model file the code was generated from")->capture_default_str();
  app.add_flag("--eval", eval, "print the eval JSON at the state instead of simulating");
  bool open_loop = false;
#ifdef KANEGEN_HAS_CONTROLLER
  app.add_flag("--open-loop", open_loop, "run without the compiled-in controller (inputs from --state)");
#endif
  // <program> sweep SWEEP.yaml ...: a Monte Carlo sweep of this model on the compiled-in code (closed loop with
  // the compiled-in controller), as `kanegen sweep` (docs/sweeps.md)
  cli::SweepCli sweep;
  CLI::App* sweep_cmd = app.add_subcommand(
      "sweep", "Monte Carlo sweep of this model on the compiled-in code and controller (docs/sweeps.md)");
  cli::add_sweep_options(sweep_cmd, sweep);
#ifdef KANEGEN_HAS_CONTROLLER
  sweep_cmd->add_flag("--open-loop", open_loop, "run the sweep without the compiled-in controller");
#endif
  try {
    cli::CommandLineArguments args(argc, argv);
    app.parse(args.argc(), args.argv());
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }

  if (sweep_cmd->parsed()) {
    return exit_status_of(program, [&] {
      auto make = [&](const Model& m) -> std::unique_ptr<Engine> {
        try {
          return std::make_unique<GeneratedEngine>(m, api);
        } catch (const std::runtime_error& e) {  // e.g. a dispersed value the compiled code keeps constant
          throw InputError(Diagnostic{sweep.sweep, 0, "",
                                      fmt::format("{}: the code compiled into {} does not fit the sweep's model "
                                                  "(every dispersed model value must be among the model's "
                                                  "parameters: when the code is generated)",
                                                  e.what(), program)});
        }
      };
      ControllerFactory controller;
#ifdef KANEGEN_HAS_CONTROLLER
      if (!open_loop) controller = [](const Model& m, long) { return kanegen_controller(m); };
#endif
      return cli::run_sweep_cli(sweep, make, controller);
    });
  }
  return exit_status_of(program, [&] {
    const Model model = load_model(model_file);
    check_mass_matrix_at_initial_state(model);
    const State state = state_path.empty() ? initial_state(model) : load_state(model, state_path);
    if (!eval) check_output_options({{"-o", sim.output}}, input_files(model, state_path));  // before any work
    std::unique_ptr<GeneratedEngine> engine_ptr;
    try {
      engine_ptr = std::make_unique<GeneratedEngine>(model, api);
    } catch (const std::runtime_error& e) {  // code and model disagree: a refused input
      fmt::print(stderr, "{}: {}\n(the code compiled into {} does not fit {}; rebuild it or pass --model)\n", program,
                 e.what(), program, model_file);
      return 2;
    }
    GeneratedEngine& engine = *engine_ptr;
    if (eval) {
      std::cout << eval_report(engine, state).dump(1) << '\n';
      return 0;
    }
    SimulationOptions opt = cli::simulation_options(sim, state);
#ifdef KANEGEN_HAS_CONTROLLER
    if (!open_loop) opt.controller = kanegen_controller(model);
#else
    (void)open_loop;
#endif
    try {
      const SimulationResult r = simulate_to_file(engine, state, opt, sim.output);
      fmt::print(stderr, "{} [generated engine, compiled in], {} rows to {}, max quaternion drift {:.2e}\n{}",
                 r.stats.summary(), r.rows, sim.output, r.max_quaternion_drift, cli::describe_quality(r.quality));
    } catch (const IntegrationError& e) {
      fmt::print(stderr, "{}: {}\nno output written\n", program, cli::describe_failure(model, e));
      return 1;
    }
    return 0;
  });
}

}  // namespace kanegen
