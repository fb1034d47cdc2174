// Shared pieces of the kanegen CLI (interface.md): one file per subcommand
// (cmd_*.cpp) registers its options and returns how to run it.
// Exit status: 0 success, 2 refused input (message names file, line, field),
// 1 failure while running.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <memory>
#include <string>

#include "engine/engine.hpp"
#include "model/model.hpp"
#include "model/state_io.hpp"

namespace kanegen::cli {

constexpr int kExitFailure = 1;
constexpr int kExitRefused = 2;

struct Subcommand {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

Subcommand add_check(CLI::App& app);
Subcommand add_compile(CLI::App& app);
Subcommand add_generate(CLI::App& app);
Subcommand add_modes(CLI::App& app);
Subcommand add_import(CLI::App& app);
Subcommand add_view(CLI::App& app);
Subcommand add_crosscheck(CLI::App& app);
Subcommand add_eval(CLI::App& app);
Subcommand add_simulate(CLI::App& app);
Subcommand add_bench(CLI::App& app);
Subcommand add_linearize(CLI::App& app);
Subcommand add_sweep(CLI::App& app);

/// load_model() plus the check that M is not singular at the initial state.
Model load_checked(const std::string& path);
/// "generated" (JIT, with the generator of codegen/) or "generic"; a compile
/// failure of the generated code is a refused input. "auto" (simulate): the
/// generated engine when its library is cached or the command needs its
/// derivatives, else a HandoverEngine: the generic engine at once, the
/// generated code built in the background and used once ready.
/// `derivatives`: whether the command needs the generated dual-number
/// Jacobians (linearize, implicit integrators); without them a first build is
/// faster (a full library already cached is used all the same).
/// `quick`: a build for a few evaluations (JitOptions::quick).
std::unique_ptr<Engine> make_engine(const Model& model, const std::string& name, bool native = false,
                                    bool derivatives = true, bool quick = false);
/// The model's initial state, or STATE.json when a path is given.
State state_for(const Model& model, const std::string& state_path);

/// The MODEL positional argument.
void add_model_option(CLI::App* c, std::string& model);
/// --engine generated|generic (|auto with `with_auto`), and --native (the
/// generated code compiled with -march=native).
void add_engine_option(CLI::App* c, std::string& engine, bool& native, bool with_auto = false);
/// Runs `kanegen compile MODEL --background` (this executable, low priority,
/// its messages to `log_path`), calls `started` once it is spawned, and waits
/// for it; throws when it fails.
void run_background_compile(const std::string& model_path, bool native, const std::string& log_path,
                            const std::function<void()>& started = {});
/// Seconds since the process started.
double seconds_since_start();

}  // namespace kanegen::cli
