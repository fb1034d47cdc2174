// kanegen eval MODEL [--state S.json] [--engine E]: the dynamics at one state, as JSON.
#include <fmt/format.h>

#include <iostream>

#include "apps/kanegen/cli_common.hpp"
#include "engine/model_checks.hpp"
#include "model/diagnostics.hpp"
#include "sim/eval_report.hpp"

namespace kanegen::cli {

namespace eval_command {

struct Options {
  std::string model, state, engine = "generated";
  bool native = false;
};

int run(const Options& o) {
  const Model model = load_checked(o.model);
  const State state = state_for(model, o.state);
  double measure = 0;
  if (const int lb = gimbal_locked_body(model, state.q.data(), kGimbalLockRefuse, &measure); lb >= 0)
    throw InputError(Diagnostic{o.state.empty() ? o.model : o.state, state.q_line > 0 ? state.q_line : 1, "q",
                                gimbal_lock_message(model, lb, state.q.data(), measure) +
                                    "; M is singular there. Expected angles away from gimbal lock"});
  auto engine = make_engine(model, o.engine, o.native, /*derivatives=*/false, /*quick=*/!o.native);
  nlohmann::ordered_json j;
  try {
    j = eval_report(*engine, state);
  } catch (const SingularMassMatrix& e) {
    // the model's own initial state was checked on load: q came from the STATE file
    throw InputError(Diagnostic{o.state.empty() ? o.model : o.state, state.q_line > 0 ? state.q_line : 1, "q",
                                fmt::format("{} at these coordinates; expected coordinates where every degree of "
                                            "freedom moves some mass",
                                            e.what())});
  }
  std::cout << j.dump(1) << '\n';
  return 0;
}

}  // namespace eval_command

Subcommand add_eval(CLI::App& app) {
  auto o = std::make_shared<eval_command::Options>();
  CLI::App* c =
      app.add_subcommand("eval", "evaluate M, F, u-dot (and the requested outputs) at one state, as JSON");
  add_model_option(c, o->model);
  c->add_option("--state", o->state, "STATE.json (default: the model's initial state)")->check(CLI::ExistingFile);
  add_engine_option(c, o->engine, o->native);
  return {c, [o] { return eval_command::run(*o); }};
}

}  // namespace kanegen::cli
