// Built-in flexible body: a uniform Euler–Bernoulli cantilever clamped at the
// body origin (model-format.md, `flexible: beam:`), discretized by finite
// elements with lumped nodal masses; its lowest modes become FlexibleData.
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
  int elements = 0;                  ///< >= 1
  int modes = 0;                     ///< >= 1, lowest modes kept
};

/// Nodes (element ends; node 1 at the clamped origin), mass-normalized modes
/// and frequencies of the cantilever. damping_ratio, K and D are left zero
/// for the caller. Throws std::invalid_argument if the spec cannot give
/// `modes` modes (e.g. more modes than finite degrees of freedom).
FlexibleData beam_modal_data(const BeamSpec& spec);

}  // namespace kanegen
