#include "codegen/jit_generator.hpp"

#include "codegen/assembler.hpp"
#include "engine/resources.hpp"

namespace kanegen::codegen {

CodeGenerator jit_code_generator(const GeneratorOptions& options) {
  CodeGenerator g;
  g.hash = generator_identity(options);
  g.generate = [options](const Model& model) {
    const AssembledFiles f = assemble(generate(model, options), template_dir(), "model.hpp");
    return GeneratedSources{f.header, f.entry, f.manifest};
  };
  if (options.udot_code == "auto") {
    // compact code shares kernels along chains: the articulated form's bodies have one shape
    GeneratorOptions compact = options;
    compact.udot_code = "compact";
    if (compact.udot_form == "auto") compact.udot_form = "articulated";
    g.generate_compact_udot = [compact](const Model& model) {
      const AssembledFiles f = assemble(generate(model, compact), template_dir(), "model.hpp");
      return GeneratedSources{f.header, f.entry, f.manifest};
    };
  }
  return g;
}

}  // namespace kanegen::codegen
