// Cross-check of two engines (generated against generic) at random states:
// the largest relative differences of q_dot, M, F, u_dot, reactions, energy,
// momentum and the named outputs (random named inputs too), each relative to
// the largest entry of the reference value.
// u_dot is judged by the residual |M u_dot - F| / (|M| |u_dot| + |F|) of the
// tested engine's u_dot in the reference M and F, since its forward error
// grows with cond(M) (reference README); its plain relative difference is
// reported too.
#pragma once

#include <map>
#include <string>

#include "engine/engine.hpp"

namespace kanegen {

struct CrosscheckResult {
  int samples = 0;
  std::map<std::string, double> worst;  ///< quantity -> largest relative difference
  /// The tolerance each quantity is held to.
  static double tolerance(const std::string& quantity);
  bool passed() const;
};

/// Random states: angles in [-pi, pi], displacements and positions in
/// [-1, 1] (a free root in a central field: 7000 km away in a random direction, plus that), modal coordinates in [-0.1, 0.1], unit quaternions, speeds and
/// inputs in [-1, 1]; with prescribed motion, times in [-1, 21] s.
CrosscheckResult crosscheck(Engine& tested, Engine& reference, int samples, unsigned seed);

}  // namespace kanegen
