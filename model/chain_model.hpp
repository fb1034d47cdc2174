// Programmatically built serial chains (benchmarks, scaling tests): n rigid
// links on revolute joints, each joint 1 m along the previous link's x axis,
// axes cycling z, y, x (a spatial chain, no planar shortcut), com at the link
// middle, diagonal inertia of a slender rod, gravity -z.
#pragma once

#include "model/model.hpp"

namespace kanegen {

Model make_chain_model(int n_bodies);

}  // namespace kanegen
