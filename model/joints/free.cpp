// Free joint: position [x y z] in J and a unit quaternion; speeds v (velocity
// of O_B relative to J) and w (angular velocity relative to J), both in B
// components (dynamics.md: the paper's choice for the bus).
#include "model/joints/joint_types.hpp"

namespace kanegen {

const JointTraits& free_traits() {
  static const JointTraits t = [] {
    JointTraits t;
    t.type = JointType::free;
    t.name = "free";
    t.coordinates = {"x", "y", "z", "qw", "qx", "qy", "qz"};
    t.speeds = {"vx", "vy", "vz", "wx", "wy", "wz"};
    t.units = {"m", "m", "m", "", "", "", ""};
    t.quaternion = 3;
    t.angular_speeds = 3;
    t.primitives = [](const Joint&) { return std::vector<JointPrimitive>{{JointPrimitive::Kind::free, Vec3::Zero(), 0, 0}}; };
    return t;
  }();
  return t;
}

}  // namespace kanegen
