// Checks of a loaded model that need its dynamics (model-format.md): the mass
// matrix must be non-singular at the model's initial state.
#pragma once

#include "model/diagnostics.hpp"
#include "model/model.hpp"

namespace kanegen {

/// Throws InputError naming the model file if M(q0) is singular.
void check_mass_matrix_at_initial_state(const Model& model);

}  // namespace kanegen
