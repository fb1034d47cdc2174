// A joint as the model file gives it (../shared/spec/model-format.md, Joints):
// its type, frame, axes, springs and dampers per coordinate, prescribed
// motion. What a joint type *is* (its coordinates, speeds, quaternion place,
// which coordinates take springs, its kinematics) is asked of its traits
// (joint_traits.hpp), one file per type in this folder.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <optional>
#include <vector>

#include "model/prescribed_motion.hpp"

namespace kanegen {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

/// Every joint type of the contract. A new type: its own file in
/// model/joints/, one entry here and one line in joint_traits.cpp.
enum class JointType { revolute, prismatic, fixed, free, universal, gimbal, cylindrical, planar, ball };

/// Spring and damper coordinates of a joint: at most three (gimbal, planar).
inline constexpr int kMaxSpringCoordinates = 3;

struct Joint {
  JointType type = JointType::fixed;
  Vec3 axis_J = Vec3::UnitZ();      ///< unit axis in the joint frame (revolute, prismatic, cylindrical)
  /// Unit axes of a universal (2) or gimbal (3) joint, each in the frame
  /// turned by the rotations before it (body-fixed sequence); empty otherwise.
  std::vector<Vec3> axes_J;
  Vec3 p_PJ = Vec3::Zero();         ///< joint frame origin in parent frame (used when node < 0)
  Mat3 R_PJ = Mat3::Identity();     ///< joint frame orientation in parent (the `rotation:`)
  int node = -1;                    ///< index into the parent's FlexibleData::nodes, or -1
  /// Spring and damper per coordinate (JointTraits::springs of them; a ball
  /// joint's damping[0] acts on its angular speeds): -k_i (q_i - rest_i) - c_i u_i.
  std::array<double, kMaxSpringCoordinates> stiffness{};
  std::array<double, kMaxSpringCoordinates> damping{};
  std::array<double, kMaxSpringCoordinates> rest{};
  /// Prescribed motion (revolute, prismatic): the coordinate is a known
  /// function of time, not a degree of freedom (no q, no u, no input).
  std::optional<PrescribedMotion> motion;
  bool prescribed() const { return motion.has_value(); }
  /// `locked: true`: the joint starts locked (model/events.hpp, dynamics.md "Locks").
  bool locked = false;
  /// Whether coordinate i has a spring or damper.
  bool has_spring(int i) const { return stiffness[i] != 0.0 || damping[i] != 0.0; }
};

}  // namespace kanegen
