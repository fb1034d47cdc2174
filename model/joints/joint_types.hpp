// The traits of each joint type, one function per file of this folder;
// joint_traits.cpp registers them.
#pragma once

#include "model/joints/joint_traits.hpp"

namespace kanegen {

const JointTraits& revolute_traits();
const JointTraits& prismatic_traits();
const JointTraits& fixed_traits();
const JointTraits& free_traits();
const JointTraits& universal_traits();
const JointTraits& gimbal_traits();
const JointTraits& cylindrical_traits();
const JointTraits& planar_traits();
const JointTraits& ball_traits();

}  // namespace kanegen
