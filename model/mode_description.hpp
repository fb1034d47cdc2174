// What each mode of a flexible body is, from its shapes and node masses alone
// (kanegen check prints it): the direction its kinetic energy takes
// (bending, torsion, axial for a slender body) and its modal effective masses,
// the FEA analyst's measure of how much of the body a mode carries.
//
// Modes are clamped at O (model-format.md). With node k's mass m_k, rotary
// inertia J_k, undeformed position rho_k and shapes Phi_k (translation),
// Psi_k (rotation), mode j's
//   modal mass     Y_jj = Sum m_k |Phi_kj|^2 + Psi_kj^T J_k Psi_kj   (1 when mass-normalized)
//   participation  L_t = Sum m_k Phi_kj                             (3, kg)
//                  L_r = Sum m_k rho_k x Phi_kj + J_k Psi_kj        (3, kg m, about O)
//   effective mass  L_t[a]^2 / Y_jj along B's axis a; effective inertia L_r[a]^2 / Y_jj about it.
// Over a complete set of modes the effective masses add up to the mass of the
// nodes that move (a clamped node is left out; and the inertias to their
// inertia about O): the fraction shows what the kept modes miss.
#pragma once

#include <string>
#include <vector>

#include "model/model.hpp"

namespace kanegen {

struct ModeDescription {
  /// e.g. "bending: deflection along x (about z)", "torsion about y", "axial along y",
  /// or, for a body that is not slender, "mostly z-translation".
  std::string shape;
  Vec3 energy_translation = Vec3::Zero();  ///< share of the mode's kinetic energy in x, y, z translation
  Vec3 energy_rotation = Vec3::Zero();     ///< share in node rotation about x, y, z
  Vec3 effective_mass = Vec3::Zero();      ///< kg along B's x, y, z
  Vec3 effective_inertia = Vec3::Zero();   ///< kg m^2 about O's x, y, z axes
};

struct FlexibleBodyModes {
  double node_mass = 0.0;                  ///< the moving nodes' mass (what the effective masses tend to)
  Vec3 node_inertia_O = Vec3::Zero();      ///< their moments of inertia about O's axes (diagonal)
  int long_axis = -1;                      ///< 0, 1, 2: the B axis a slender body lies along; -1: not slender
  std::vector<ModeDescription> modes;
};

/// The modes of a flexible body (body.flex must be set).
FlexibleBodyModes describe_modes(const Body& body);

}  // namespace kanegen
