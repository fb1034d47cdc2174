// kanegen compile MODEL: build the model's generated code into the JIT cache
// (no run). `simulate --engine auto` starts one with --background when no
// compiled code of its model is cached, and hands over to it when it is done.
#include <unistd.h>

#include <fmt/format.h>

#include "apps/kanegen/cli_common.hpp"
#include "codegen/jit_generator.hpp"
#include "engine/jit.hpp"

namespace kanegen::cli {

namespace compile_command {

struct Options {
  std::string model;
  bool native = false, derivatives = false, background = false;
};

int run(const Options& o) {
  if (o.background && nice(10) == -1) {
    // a background build at normal priority still builds: nothing to report
  }
  const Model model = load_checked(o.model);
  JitOptions jit;
  jit.native = o.native;
  jit.derivatives = o.derivatives;
  jit.quiet = o.background;
  try {
    (void)jit_load(model, codegen::jit_code_generator(), jit);
  } catch (const JitError& e) {
    throw InputError(Diagnostic{model.source_path, 0, "", e.what()});
  }
  return 0;
}

}  // namespace compile_command

Subcommand add_compile(CLI::App& app) {
  auto o = std::make_shared<compile_command::Options>();
  CLI::App* c = app.add_subcommand(
      "compile", "build a model's generated code into the JIT cache (what simulate, eval and linearize load)");
  add_model_option(c, o->model);
  c->add_flag("--native", o->native, "for this machine's CPU (-march=native)");
  c->add_flag("--derivatives", o->derivatives,
              "also the dual-number Jacobians (linearize, implicit integrators; a longer build)");
  c->add_flag("--background", o->background, "at low priority (nice 10) and without messages");
  return {c, [o] { return compile_command::run(*o); }};
}

}  // namespace kanegen::cli
