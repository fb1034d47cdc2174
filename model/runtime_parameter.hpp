// One scalar runtime parameter of a model (model/parameters.hpp has what they
// are and the functions on them).
#pragma once

#include <string>

namespace kanegen {

enum class ParameterKind {
  mass, com, inertia, stiffness, damping, rest, frequency, damping_ratio, gravity,
  position,      ///< the joint frame's origin in the parent frame (model components), index 0-2
  misalignment,  ///< the joint frame turned by Rz(z) Ry(y) Rx(x) after its nominal rotation, index 0-2 (rad)
  central,       ///< the central field (gravity: central:): index 0 mu [m^3/s^2], 1 J2
};

struct RuntimeParameter {
  std::string name;   ///< scalar entry, e.g. "bus.inertia.xy", "ant1.frequency2", "gravity.z"
  std::string unit;
  ParameterKind kind = ParameterKind::mass;
  int body = -1;      ///< -1 for gravity
  int index = 0;      ///< component (com, gravity: 0-2; inertia: xx yy zz xy xz yz = 0-5) or mode (0-based)
  double nominal = 0.0;
};

}  // namespace kanegen
