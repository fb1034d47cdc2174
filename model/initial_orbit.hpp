// `initial: orbit:` (model-format.md, "Gravity"): the whole system's centre
// of mass placed on an orbit of the central field, the rest of `initial:`
// describing the configuration and motion relative to it; with
// `attitude: lvlh` the free root body aligned with the orbit frame (x along
// track, y against the orbit normal, z to nadir) and turning with it.
#pragma once

#include "model/model.hpp"
#include "model/orbit.hpp"

namespace kanegen {

/// Sets the free root body's position and velocity in model.q0 / model.u0 (and with lvlh its quaternion and
/// angular velocity: the orbit frame's, turned by the offsets) so that the system's centre of mass is on the orbit. `root`: the free root body's index.
void place_on_orbit(Model& model, int root, const InitialOrbit& orbit);

/// The root body's coordinate and speed names an orbit sets (its position and velocity; with lvlh also its
/// quaternion and angular velocity): what `initial:` and a sweep may not set as well.
struct OrbitSetNames {
  std::vector<std::string> q, u;
};
OrbitSetNames orbit_set_names(const std::string& root, bool lvlh);

}  // namespace kanegen
