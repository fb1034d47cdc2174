// A random serial chain for tests: revolute joints with random axes, joint
// frames, inertias, springs and dampers, under gravity (the kind of
// ../shared/bench-models/chain_*.yaml, which a clone of this repository alone
// does not have), as model-file text.
#pragma once

#include <fmt/format.h>

#include <cmath>
#include <random>
#include <string>

namespace kanegen::test {

/// An n-link chain of revolute joints, random axes, frames, inertias, springs and dampers, under gravity:
/// the bench models' kind (../shared/bench-models/chain_*.yaml), generated here with a fixed seed.
inline std::string random_chain(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::string s = fmt::format("name: chain{}\ngravity: [0, 0, -9.81]\nbodies:\n", n);
  for (int i = 1; i <= n; ++i) {
    double ax = U(rng), ay = U(rng), az = U(rng);
    const double norm = std::sqrt(ax * ax + ay * ay + az * az);
    ax /= norm, ay /= norm, az /= norm;
    const double a = 0.02 + 0.01 * std::abs(U(rng)), b = 0.02 + 0.01 * std::abs(U(rng)), c = 0.03 + 0.01 * std::abs(U(rng));
    s += fmt::format(
        "  - name: link{}\n    parent: {}\n"
        "    joint: {{type: revolute, axis: [{:.17g}, {:.17g}, {:.17g}], position: [{}, {}, {}], rotation: {{rpy: [{}, {}, {}]}}, "
        "stiffness: {}, damping: {}, rest: {}}}\n"
        "    mass: {}\n    com: [{}, {}, {}]\n    inertia: [{}, {}, {}, {}, {}, {}]\n",
        i, i == 1 ? "ground" : fmt::format("link{}", i - 1), ax, ay, az, i == 1 ? 0.0 : 0.3 * U(rng),
        i == 1 ? 0.0 : 0.3 * U(rng), i == 1 ? 0.0 : 0.3 * U(rng), 3 * U(rng), 1.5 * U(rng), 3 * U(rng),
        0.5 + 0.5 * std::abs(U(rng)), 0.05 + 0.1 * std::abs(U(rng)), 0.2 * U(rng), 0.5 + 1.5 * std::abs(U(rng)),
        0.15 * U(rng), 0.15 * U(rng), 0.15 * U(rng), b + c, a + c, a + b, 0.1 * a * U(rng), 0.1 * b * U(rng),
        0.1 * c * U(rng));
  }
  return s;
}

}  // namespace kanegen::test
