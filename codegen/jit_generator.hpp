// The generator as the JIT sees it (engine/jit.hpp's CodeGenerator): generate,
// assemble with the installed templates, and the generator's hash for the
// cache key. What the kanegen CLI, the tests and the benchmarks pass to jit_load().
#pragma once

#include "codegen/generator.hpp"
#include "engine/jit.hpp"

namespace kanegen::codegen {

CodeGenerator jit_code_generator(const GeneratorOptions& options = {});

}  // namespace kanegen::codegen
