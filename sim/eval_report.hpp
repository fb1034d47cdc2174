// The JSON document of `kanegen eval` (interface.md).
#pragma once

#include <nlohmann/json.hpp>

#include <stdexcept>

#include "engine/engine.hpp"
#include "model/state_io.hpp"

namespace kanegen {

/// A result is not finite (the state or the model's values overflow double
/// precision): a failure while running (exit 1), naming the quantity and the state.
class NonFiniteResult : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Evaluates q_dot, M, F, u_dot and, as the model's outputs ask, energy,
/// momentum and reactions at `state`. Throws SingularMassMatrix, or
/// NonFiniteResult: a document never holds a null, NaN or infinity.
nlohmann::ordered_json eval_report(Engine& engine, const State& state);

}  // namespace kanegen
