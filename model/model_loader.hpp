// YAML topology file -> validated, read-only Model (model-format.md).
#pragma once

#include <string>

#include "model/diagnostics.hpp"
#include "model/model.hpp"

namespace kanegen {

/// Reads and validates a model file and every modal file it names. On any
/// fault throws InputError with one Diagnostic per fault found (all of them,
/// not only the first), each naming file, line and field.
/// Under `initial: orbit:` the root's state is not yet placed (Model::initial_orbit and orbit_root are set):
/// placing it needs the system's centre of mass, from the dynamics; engine/load_model.hpp's load_model()
/// parses and places.
Model parse_model(const std::string& path);

}  // namespace kanegen
