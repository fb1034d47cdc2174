// The motion relative to the system's centre of mass (Koenig's theorem), formed
// without the orbit's large numbers: for a system whose root joints are all free,
// the state is moved so that the first free root's origin is at N's origin and
// boosted by -v_c (a Galilean change of frame: every free root's velocity less the
// centre of mass's), and the engine's kinetic energy and angular momentum at that
// state are T_c and H_c, those about the centre of mass. Orbit and attitude apart:
// T = 1/2 M |v_c|^2 + T_c, H = M r_c x v_c + H_c (docs/decisions.md, "Reports in
// orbit"). The engine's own parameters (masses a sweep disperses) apply.
#pragma once

#include <optional>

#include "engine/engine.hpp"

namespace kanegen {

struct MotionAboutCentreOfMass {
  double mass = 0.0;
  Vec3 v_c_N = Vec3::Zero();  ///< the centre of mass's velocity, N components
  double T_c = 0.0;           ///< kinetic energy of the motion relative to the centre of mass
  Vec3 H_c_N = Vec3::Zero();  ///< angular momentum about the centre of mass, N components
};

/// Whether every root joint is free (the frame change is then a change of those joints' coordinates).
bool all_roots_free(const Model& model);

/// The motion about the centre of mass at (t, q, u); nullopt unless all_roots_free(model) and mass > 0.
std::optional<MotionAboutCentreOfMass> motion_about_centre_of_mass(Engine& engine, double t, const VecX& q,
                                                                   const VecX& u);

}  // namespace kanegen
