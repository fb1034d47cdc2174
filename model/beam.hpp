// Built-in flexible body: a uniform Euler–Bernoulli cantilever clamped at the
// body origin (model-format.md `flexible: beam:`, extended in docs/models.md),
// discretized by finite elements with lumped nodal masses and rotary
// inertias; its lowest modes and, for foreshortening, the second-order node
// displacements Gamma_k (dynamics.md) become FlexibleData.
#pragma once

#include <array>
#include <optional>

#include "model/model.hpp"

namespace kanegen {

struct BeamSpec {
  double length = 0.0;               ///< > 0
  int axis = 0;                      ///< beam axis in the body frame: 0 = x, 1 = y, 2 = z
  int sign = 1;                      ///< +1 or -1 (direction -x, -y, -z)
  double mass_per_length = 0.0;      ///< > 0, kg/m
  std::array<double, 2> EI{};        ///< bending stiffness about the two normal axes in cyclic
                                     ///< order: x -> [y, z], y -> [z, x], z -> [x, y]
  std::optional<double> GJ;          ///< torsional stiffness, optional
  std::optional<double> EA;          ///< axial stiffness, optional
  /// Rotary inertia per length of the cross-section about the two normal axes
  /// (rho I, kg m; same order as EI); 0: Euler–Bernoulli (the bending slopes
  /// are condensed statically).
  std::array<double, 2> rotary_inertia{0.0, 0.0};
  /// Polar inertia per length (rho J, kg m) for torsion; when not given, the
  /// perpendicular-axis sum of rotary_inertia. Torsion modes need GJ and a
  /// polar inertia > 0.
  std::optional<double> polar_inertia;
  int elements = 0;                  ///< >= 1
  int modes = 0;                     ///< >= 1, lowest modes kept
  bool second_order = true;          ///< compute Gamma (foreshortening); elements x modes^2 entries
};

/// Nodes (element ends; node 1 at the clamped origin, carried rigidly), their
/// masses and rotary inertias, the mass-normalized modes (bending in both
/// planes, torsion with GJ, axial with EA), their frequencies, and the
/// second-order data Gamma_k along the beam (for every node but the root).
/// damping_ratio, K and D are left zero for the caller. Throws
/// std::invalid_argument if the spec cannot give `modes` modes.
FlexibleData beam_modal_data(const BeamSpec& spec);

}  // namespace kanegen
