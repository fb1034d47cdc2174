// Checks of a loaded model that need its dynamics (model-format.md): the mass
// matrix must be non-singular at the model's initial state.
#pragma once

#include "model/diagnostics.hpp"
#include "model/model.hpp"

namespace kanegen {

/// Throws InputError naming the model file if M(q0) is singular, a gimbal
/// is in gimbal lock at q0, or (in a central field) a mass element is at the
/// attracting centre (check_mass_elements_off_the_centre).
void check_mass_matrix_at_initial_state(const Model& model);

/// In a central field: throws InputError naming each body with a mass element
/// (its rigid part or a node) where the field or its gradient is not a finite
/// number at q0 (at N's origin: r = 0).
void check_mass_elements_off_the_centre(const Model& model);

/// The first body whose joint is within `limit` of gimbal lock at q
/// (|det Gamma| <= limit, model/joints/joint_traits.hpp), or -1; its measure
/// in `measure`.
int gimbal_locked_body(const Model& model, const double* q, double limit, double* measure = nullptr);

/// "joint of 'name' (gimbal) is in gimbal lock: |det Gamma| = ..., angles [..]" for messages.
std::string gimbal_lock_message(const Model& model, int body, const double* q, double measure);

}  // namespace kanegen
