// The whole spacecraft's mass, centre of mass and inertia at a state, from the
// generic engine's kinematics and body terms (dynamics/): every body's mass,
// first moment and inertia about its origin O_B at its current deflection,
// carried to N axes and to the system's centre of mass.
#pragma once

#include "model/model.hpp"
#include "model/state_io.hpp"

namespace kanegen {

struct SystemMassProperties {
  double mass = 0.0;
  Vec3 com_N = Vec3::Zero();     ///< centre of mass from N's origin, N components
  Mat3 J_com_N = Mat3::Zero();   ///< inertia about the centre of mass, N axes
  Vec3 principal_moments = Vec3::Zero();  ///< ascending
  Mat3 principal_axes_N = Mat3::Identity();  ///< columns: the principal axes in N (right-handed)
};

SystemMassProperties system_mass_properties(const Model& model, const State& state);

}  // namespace kanegen
