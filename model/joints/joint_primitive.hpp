// The elementary motions a joint is made of, in order from the joint frame J
// to the body frame B: a rotation about a constant axis, a translation along a
// constant axis (each axis in the frame reached so far), a spherical rotation
// by a unit quaternion with the angular velocity as speeds, or the free
// joint's translation and rotation. Every joint type of model/joints/ is a
// short list of them; joint_kinematics.hpp turns a list into R_JB, the offset,
// the motion subspace and its rate, for numbers and symbols alike.
#pragma once

#include <Eigen/Dense>

namespace kanegen {

/// The most coordinates and speeds one joint has (the free joint's 7 and 6).
inline constexpr int kMaxJointCoordinates = 7;
inline constexpr int kMaxJointSpeeds = 6;

struct JointPrimitive {
  enum class Kind {
    rotation,     ///< Rot(axis, q[q]) with rate u[u]
    translation,  ///< axis q[q] with rate u[u]
    sphere,       ///< R(quaternion q[q..q+3]); u[u..u+2] = angular velocity in the new frame
    free          ///< position q[q..q+2] in the frame so far, quaternion q[q+3..q+6];
                  ///< u[u..u+2] velocity and u[u+3..u+5] angular velocity, new frame components
  };
  Kind kind = Kind::rotation;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  ///< rotation and translation
  int q = 0;                                        ///< first coordinate, within the joint's q
  int u = 0;                                        ///< first speed, within the joint's u
};

}  // namespace kanegen
