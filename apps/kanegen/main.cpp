// kanegen: the command-line interface (interface.md); one file per subcommand.
// Exit status: 0 success, 2 refused input (message names file, line, field),
// 1 failure while running.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "apps/common/command_line_arguments.hpp"
#include "apps/kanegen/cli_common.hpp"
#include "engine/jit.hpp"
#include "model/diagnostics.hpp"
#include "model/output_file.hpp"

using namespace kanegen;

int main(int argc, char** argv) {
  CLI::App app{"kanegen: Kane's-method equations of motion for multibody spacecraft"};
  app.require_subcommand(1);
  const std::vector<cli::Subcommand> commands = {cli::add_check(app),      cli::add_generate(app),
                                                 cli::add_modes(app),      cli::add_crosscheck(app),
                                                 cli::add_eval(app),       cli::add_simulate(app),
                                                 cli::add_bench(app),      cli::add_linearize(app),
                                                 cli::add_sweep(app),      cli::add_compile(app),
                                                 cli::add_import(app),      cli::add_view(app)};
  try {
    cli::CommandLineArguments args(argc, argv);
    app.parse(args.argc(), args.argv());
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : cli::kExitRefused;
  }
  try {
    for (const auto& c : commands)
      if (c.app->parsed()) return c.run();
  } catch (const InputError& e) {
    for (const Diagnostic& d : e.diagnostics()) fmt::print(stderr, "{}\n", d.str());
    return cli::kExitRefused;
  } catch (const OutputRefused& e) {
    fmt::print(stderr, "kanegen: cannot write output {}\n", e.what());
    return cli::kExitRefused;
  } catch (const std::exception& e) {
    fmt::print(stderr, "kanegen: {}\n", e.what());
    return cli::kExitFailure;
  }
  return cli::kExitFailure;
}
