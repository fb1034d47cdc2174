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
    // in the form the main code has (auto: fewer operations); tree_15's composite compact code ran 11 % faster
    // than its articulated compact code
    GeneratorOptions compact = options;
    compact.udot_code = "compact";
    g.generate_compact_udot = sources_with(compact);
    GeneratorOptions straight = options;
    straight.udot_code = "straight-line";
    g.generate_straight_udot = sources_with(straight);
  }
  return g;
}

}  // namespace kanegen::codegen
