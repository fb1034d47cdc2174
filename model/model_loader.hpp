// YAML topology file -> validated, read-only Model (model-format.md).
#pragma once

#include <string>

#include "model/diagnostics.hpp"
#include "model/model.hpp"

namespace kanegen {

/// Reads and validates a model file and every modal file it names. On any
/// fault throws InputError with one Diagnostic per fault found (all of them,
/// not only the first), each naming file, line and field.
Model load_model(const std::string& path);

}  // namespace kanegen
