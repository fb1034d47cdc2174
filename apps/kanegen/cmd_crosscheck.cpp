// kanegen crosscheck MODEL: generated against generic engine at random states.
#include <fmt/format.h>

#include "apps/kanegen/cli_common.hpp"
#include "engine/generic_engine.hpp"
#include "sim/crosscheck.hpp"

namespace kanegen::cli {

namespace crosscheck_command {

struct Options {
  std::string model;
  int samples = 20;
  unsigned seed = 1;
};

int run(const Options& o) {
  const Model model = load_checked(o.model);
  auto generated = make_engine(model, "generated");
  GenericEngine generic(model);
  const CrosscheckResult r = crosscheck(*generated, generic, o.samples, o.seed);
  fmt::print("crosscheck {}: generated vs generic at {} random states (seed {})\n", model.name, r.samples, o.seed);
  for (const auto& [q, v] : r.worst) {
    const double tol = CrosscheckResult::tolerance(q);
    fmt::print("  {:<18} {:.3e}   {}\n", q, v,
               tol > 1 ? "(not judged: grows with cond(M))"
                       : fmt::format("tolerance {:.0e}{}", tol, v <= tol ? "" : "  FAILED"));
  }
  fmt::print("{}\n", r.passed() ? "passed" : "FAILED");
  return r.passed() ? 0 : kExitFailure;
}

}  // namespace crosscheck_command

Subcommand add_crosscheck(CLI::App& app) {
  auto o = std::make_shared<crosscheck_command::Options>();
  CLI::App* c = app.add_subcommand("crosscheck", "compare generated and generic engines at random states");
  add_model_option(c, o->model);
  c->add_option("--samples", o->samples, "number of random states")->capture_default_str()->check(CLI::PositiveNumber);
  c->add_option("--seed", o->seed, "random seed")->capture_default_str();
  return {c, [o] { return crosscheck_command::run(*o); }};
}

}  // namespace kanegen::cli
