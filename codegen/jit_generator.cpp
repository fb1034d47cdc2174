#include "codegen/jit_generator.hpp"

#include "codegen/assembler.hpp"
#include "engine/resources.hpp"

namespace kanegen::codegen {

CodeGenerator jit_code_generator(const GeneratorOptions& options) {
  CodeGenerator g;
  g.hash = generator_identity(options);
  auto sources_with = [](const GeneratorOptions& o) {
    return [o](const Model& model) {
      const AssembledFiles f = assemble(generate(model, o), template_dir(), "model.hpp");
      return GeneratedSources{f.header, f.entry, f.manifest};
    };
  };
  g.generate = sources_with(options);
  if (options.udot_code == "auto") {
    // compact code shares kernels along chains: the articulated form's bodies have one shape
    GeneratorOptions compact = options;
    compact.udot_code = "compact";
    if (compact.udot_form == "auto") compact.udot_form = "articulated";
    g.generate_compact_udot = sources_with(compact);
  }
  return g;
}

}  // namespace kanegen::codegen
