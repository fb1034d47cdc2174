// A model file read, validated and made ready to run: model/model_loader.hpp's
// parse_model(), then what needs the dynamics (engine/initial_orbit.hpp: the
// system placed on its `initial: orbit:`).
#pragma once

#include <string>

#include "model/model.hpp"
#include "model/model_loader.hpp"

namespace kanegen {

/// Reads and validates a model file and every modal file it names (parse_model: InputError with file, line
/// and field for every fault) and places the system on its initial orbit if it has one.
Model load_model(const std::string& path);

}  // namespace kanegen
