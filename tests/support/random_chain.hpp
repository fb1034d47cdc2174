// A random serial chain or binary tree for tests: revolute joints with random axes, joint
// frames, inertias, springs and dampers, under gravity (the kind of
// ../shared/bench-models/chain_*.yaml, which a clone of this repository alone
// does not have), as model-file text.
#pragma once

#include <fmt/format.h>

#include <cmath>
#include <random>
#include <string>

namespace kanegen::test {

namespace detail {

/// n bodies link1..linkn, body i on parent_of(i) (0: the ground), revolute with random axes, frames,
/// inertias, springs and dampers, under gravity; body i prismatic where prismatic(i).
template <class Parent, class Prismatic>
std::string random_bodies(const std::string& name, int n, unsigned seed, Parent parent_of, Prismatic prismatic) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::string s = fmt::format("name: {}\ngravity: [0, 0, -9.81]\nbodies:\n", name);
  for (int i = 1; i <= n; ++i) {
    double ax = U(rng), ay = U(rng), az = U(rng);
    const double norm = std::sqrt(ax * ax + ay * ay + az * az);
    ax /= norm, ay /= norm, az /= norm;
    const double a = 0.02 + 0.01 * std::abs(U(rng)), b = 0.02 + 0.01 * std::abs(U(rng)), c = 0.03 + 0.01 * std::abs(U(rng));
    const int p = parent_of(i);
    s += fmt::format(
        "  - name: link{}\n    parent: {}\n"
        "    joint: {{type: {}, axis: [{:.17g}, {:.17g}, {:.17g}], position: [{}, {}, {}], rotation: {{rpy: [{}, {}, {}]}}, "
        "stiffness: {}, damping: {}, rest: {}}}\n"
        "    mass: {}\n    com: [{}, {}, {}]\n    inertia: [{}, {}, {}, {}, {}, {}]\n",
        i, p == 0 ? "ground" : fmt::format("link{}", p), prismatic(i) ? "prismatic" : "revolute", ax, ay, az,
        i == 1 ? 0.0 : 0.3 * U(rng), i == 1 ? 0.0 : 0.3 * U(rng), i == 1 ? 0.0 : 0.3 * U(rng), 3 * U(rng),
        1.5 * U(rng), 3 * U(rng), 0.5 + 0.5 * std::abs(U(rng)), 0.05 + 0.1 * std::abs(U(rng)), 0.2 * U(rng),
        0.5 + 1.5 * std::abs(U(rng)), 0.15 * U(rng), 0.15 * U(rng), 0.15 * U(rng), b + c, a + c, a + b,
        0.1 * a * U(rng), 0.1 * b * U(rng), 0.1 * c * U(rng));
  }
  return s;
}

}  // namespace detail

/// An n-link chain of revolute joints, random axes, frames, inertias, springs and dampers, under gravity:
/// the bench models' kind (../shared/bench-models/chain_*.yaml), generated here with a fixed seed.
inline std::string random_chain(int n, unsigned seed) {
  return detail::random_bodies(
      fmt::format("chain{}", n), n, seed, [](int i) { return i - 1; }, [](int) { return false; });
}

/// An n-body binary tree listed breadth-first (body i on body i / 2), random revolute axes and frames, body 5
/// prismatic: the kind of ../shared/bench-models/tree_15.yaml, whose bodies other than their parent's first
/// (main) child take the generator's screw turns (codegen/joint_frames.hpp).
inline std::string random_tree(int n, unsigned seed) {
  return detail::random_bodies(
      fmt::format("tree{}", n), n, seed, [](int i) { return i / 2; }, [](int i) { return i == 5; });
}

}  // namespace kanegen::test
