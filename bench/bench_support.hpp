// Shared by the benchmarks: a reproducible state near the model's initial one.
#pragma once

#include <random>

#include "model/model.hpp"
#include "model/state_io.hpp"

namespace kanegen::bench {

/// q0 perturbed by up to 0.3 per coordinate (quaternions renormalized), speeds
/// up to `speed` in magnitude, zero inputs.
inline State random_state(const Model& model, unsigned seed, double speed = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  State s = initial_state(model);
  for (int i = 0; i < model.nq; ++i) s.q(i) += 0.3 * U(rng);
  for (const Body& b : model.bodies)
    if (b.joint.type == JointType::free) s.q.segment<4>(b.q_joint + 3).normalize();
  for (int i = 0; i < model.nu; ++i) s.u(i) = speed * U(rng);
  return s;
}

}  // namespace kanegen::bench
