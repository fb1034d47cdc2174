// `initial: orbit:` (model-format.md, "Gravity"): the whole system's centre
// of mass placed on an orbit of the central field, the rest of `initial:`
// describing the configuration and motion relative to it; with
// `attitude: lvlh` the free root body aligned with the orbit frame (x along
// track, y against the orbit normal, z to nadir) and turning with it. Here:
// the names an orbit sets; the placing itself (it needs the system's centre
// of mass) is engine/initial_orbit.hpp's.
#pragma once

#include "model/model.hpp"
#include "model/orbit.hpp"

namespace kanegen {

/// The root body's coordinate and speed names an orbit sets (its position and velocity; with lvlh also its
/// quaternion and angular velocity): what `initial:` and a sweep may not set as well.
struct OrbitSetNames {
  std::vector<std::string> q, u;
};
OrbitSetNames orbit_set_names(const std::string& root, bool lvlh);

}  // namespace kanegen
