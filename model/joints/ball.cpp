// Ball (spherical) joint: orientation by a unit quaternion, speeds the angular
// velocity of B relative to J in B components; normalized and stabilized as a
// free joint's quaternion; a damper (no spring) on the angular velocity.
#include "model/joints/joint_types.hpp"

namespace kanegen {

const JointTraits& ball_traits() {
  static const JointTraits t = [] {
    JointTraits t;
    t.type = JointType::ball;
    t.name = "ball";
    t.coordinates = {"qw", "qx", "qy", "qz"};
    t.speeds = {"wx", "wy", "wz"};
    t.units = {"", "", "", ""};
    t.quaternion = 0;
    t.angular_speeds = 0;
    t.damping_only = true;
    t.primitives = [](const Joint&) { return std::vector<JointPrimitive>{{JointPrimitive::Kind::sphere, Vec3::Zero(), 0, 0}}; };
    return t;
  }();
  return t;
}

}  // namespace kanegen
