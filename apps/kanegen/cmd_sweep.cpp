// kanegen sweep SWEEP.yaml [-o DIR] [--threads N] [--run K] [--shard i/N] [--merge DIR ...]:
// a Monte Carlo sweep (sim/sweep.hpp, docs/sweeps.md) on the engine the
// sweep file names, open loop (a closed-loop sweep runs in an ahead-of-time
// simulator with its controller compiled in, or from Python); the driver is
// apps/common/sweep_cli.hpp.
#include "apps/common/sweep_cli.hpp"
#include "apps/kanegen/cli_common.hpp"

namespace kanegen::cli {

Subcommand add_sweep(CLI::App& app) {
  auto o = std::make_shared<SweepCli>();
  CLI::App* c = app.add_subcommand("sweep", "Monte Carlo sweep: dispersed runs of a model, a table, a summary (docs/sweeps.md)");
  add_sweep_options(c, *o);
  return {c, [o] {
            const std::string engine = load_sweep_spec(o->sweep).engine;
            return run_sweep_cli(*o, [engine](const Model& m) { return make_engine(m, engine); });
          }};
}

}  // namespace kanegen::cli
