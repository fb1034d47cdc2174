// Second-order (foreshortening) data Gamma_k for modal data that lacks it,
// when its nodes form a chain from the body origin (a boom, an antenna):
// each element a -> b of the chain (length l, direction e) shortens by
// Integral w_i'(s).w_j'(s) ds of the modes' transverse deflections w, the
// cubic Hermite interpolation of the end deflections (the part of Phi across
// e) and the end slopes (Psi x e, the turn of the tangent), and every node
// beyond it moves back along e by that much:
//   Gamma_k = - Sum_{elements before k} (Integral w_i'.w_j' ds) e.
// For the built-in beam this is exactly the Gamma it computes itself
// (dynamics.md); other structures need it from their FEA
// (docs/second_order.md).
#pragma once

#include <string>

#include "model/model.hpp"

namespace kanegen {

/// Fills flex.Gamma from the chain of its nodes. Throws std::invalid_argument
/// saying why when the nodes do not form a chain from the body origin.
void compute_chain_second_order(FlexibleData& flex);

}  // namespace kanegen
