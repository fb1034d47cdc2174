#include "apps/kanegen/cli_common.hpp"

#include <fmt/format.h>

#include "codegen/jit_generator.hpp"
#include "engine/generic_engine.hpp"
#include "engine/jit.hpp"
#include "engine/model_checks.hpp"
#include "model/diagnostics.hpp"
#include "model/model_loader.hpp"

namespace kanegen::cli {

Model load_checked(const std::string& path) {
  Model model = load_model(path);
  check_mass_matrix_at_initial_state(model);
  return model;
}

std::unique_ptr<Engine> make_engine(const Model& model, const std::string& name, bool native, bool derivatives,
                                    bool quick) {
  if (name == "generic") return std::make_unique<GenericEngine>(model);
  if (name == "generated") {
    try {
      JitOptions jit;
      jit.native = native;
      jit.derivatives = derivatives;
      jit.quick = quick;
      return jit_load(model, codegen::jit_code_generator(), jit);
    } catch (const JitError& e) {  // the generated code of this model does not compile
      throw InputError(Diagnostic{model.source_path, 0, "", e.what()});
    }
  }
  throw InputError(
      Diagnostic{"--engine", 0, "", fmt::format("unknown engine '{}'; expected generated or generic", name)});
}

State state_for(const Model& model, const std::string& state_path) {
  return state_path.empty() ? initial_state(model) : load_state(model, state_path);
}

void add_model_option(CLI::App* c, std::string& model) {
  c->add_option("MODEL", model, "model file (YAML, model-format.md)")->required()->check(CLI::ExistingFile);
}

void add_engine_option(CLI::App* c, std::string& engine, bool& native) {
  c->add_option("--engine", engine,
                "generated: the model's generated code (JIT-compiled, cached); generic: the numeric path")
      ->check(CLI::IsMember({"generated", "generic"}))
      ->capture_default_str();
  c->add_flag("--native", native,
              "compile the generated code for this machine's CPU (-march=native): faster, not portable");
}

}  // namespace kanegen::cli
