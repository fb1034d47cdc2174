// Where kanegen finds its own files at run time, relative to the program (or
// shared library) it runs in, never through a path compiled in: the install
// layout, which the build tree mirrors,
//   <prefix>/bin/kanegen
//   <prefix>/share/kanegen/templates/   model.hpp.in, entry.cpp.in (the generator's)
//   <prefix>/include/kanegen/           engine/generated_api.h, ... (for JIT compiles)
// $KANEGEN_DATA_DIR (the share/kanegen directory) and $KANEGEN_INCLUDE_DIR
// override them.
#pragma once

#include <string>

namespace kanegen {

/// share/kanegen of this installation (or build tree).
std::string data_dir();
/// data_dir() + "/templates".
std::string template_dir();
/// include/kanegen of this installation (or build tree).
std::string include_dir();

}  // namespace kanegen
