// kanegen bench MODEL...: work-precision (error against wall time).
#include "apps/kanegen/cli_common.hpp"
#include "sim/work_precision.hpp"

namespace kanegen::cli {

Subcommand add_bench(CLI::App& app) {
  auto opt = std::make_shared<bench::BenchOptions>();
  auto models = std::make_shared<std::vector<std::string>>();
  auto suite = std::make_shared<std::string>();
  CLI::App* c =
      app.add_subcommand("bench", "work-precision: error against wall time for models x engines x integrators");
  c->add_option("MODEL", *models, "model files (YAML)")->check(CLI::ExistingFile);
  c->add_option("--engines", opt->engines, "engines to compare")->delimiter(',')->capture_default_str();
  c->add_option("--integrators", opt->integrators, "integrators (cvode-bdf-fd: BDF with finite-difference Jacobian)")
      ->delimiter(',')
      ->capture_default_str();
  c->add_option("--tolerances", opt->tolerances, "rtol sweep (atol = 1e-2 rtol) [1e-4,1e-6,1e-8,1e-10]")
      ->delimiter(',');
  c->add_option("--rk4-steps", opt->rk4_steps,
                "rk4 step sizes [s] (default: 64,16,4,1 x the reference's mean step)")
      ->delimiter(',');
  c->add_option("--t-end", opt->t_end,
                "simulated time [s] (default: from the model's comments, 'bench: t_end = T', else 10)");
  c->add_option("--repeats", opt->repeats, "timed runs per point (median)")->capture_default_str();
  c->add_option("--max-run-seconds", opt->max_run_seconds, "time budget of one run")->capture_default_str();
  c->add_option("--out", opt->out_dir, "output directory")->capture_default_str();
  c->add_option("--suite", *suite, "extreme: also models/extreme/*.yaml");
  c->add_flag("--quick", opt->quick, "2 tolerances, 2 rk4 steps, 1 repeat");
  c->add_flag("!--no-plot", opt->plot, "skip the PNGs");
  return {c, [opt, models, suite] {
            opt->make_engine = [](const Model& m, const std::string& name) { return make_engine(m, name); };
            return bench::run_bench(*models, *opt, *suite);
          }};
}

}  // namespace kanegen::cli
