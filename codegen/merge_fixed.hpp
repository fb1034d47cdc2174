// Specialization of the tree before the symbolic formulation: a rigid body on
// a `fixed` joint (not at a flexible node) moves with its parent, so its mass
// is merged into the parent's rigid part and its children are re-attached to
// the parent with composed joint frames (a body fixed to ground is kept: its
// terms vanish). The merged model has the same q and u layout.

#pragma once

#include "model/model.hpp"

namespace kanegen::codegen {

Model merge_fixed_bodies(const Model& model);

}  // namespace kanegen::codegen
