// The JSON document of `kanegen eval` (interface.md).
#pragma once

#include <nlohmann/json.hpp>

#include "engine/engine.hpp"
#include "model/state_io.hpp"

namespace kanegen {

/// Evaluates q_dot, M, F, u_dot and, as the model's outputs ask, energy,
/// momentum and reactions at `state`. Throws SingularMassMatrix.
nlohmann::ordered_json eval_report(Engine& engine, const State& state);

}  // namespace kanegen
