// Placing the system on its `initial: orbit:` (model-format.md, "Gravity";
// model/initial_orbit.hpp has the names an orbit sets): the free root body's
// position and velocity chosen so that the system's centre of mass, computed
// by the dynamics, is on the orbit.
#pragma once

#include "model/initial_orbit.hpp"
#include "model/model.hpp"
#include "model/orbit.hpp"

namespace kanegen {

/// Sets the free root body's position and velocity in model.q0 / model.u0 (and with lvlh its quaternion and
/// angular velocity: the orbit frame's, turned by the offsets) so that the system's centre of mass is on the
/// orbit. `root`: the free root body's index.
void place_on_orbit(Model& model, int root, const InitialOrbit& orbit);

}  // namespace kanegen
