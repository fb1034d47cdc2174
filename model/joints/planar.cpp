// Planar joint: translation along J's x and y, then rotation about z
// (coordinates x, y, angle; orient the plane with the joint's rotation).
#include "model/joints/joint_types.hpp"

namespace kanegen {

const JointTraits& planar_traits() {
  static const JointTraits t = [] {
    JointTraits t;
    t.type = JointType::planar;
    t.name = "planar";
    t.coordinates = {"x", "y", "angle"};
    t.speeds = {"x_rate", "y_rate", "angle_rate"};
    t.units = {"m", "m", "rad"};
    t.springs = 3;
    t.primitives = [](const Joint&) {
      return std::vector<JointPrimitive>{{JointPrimitive::Kind::translation, Vec3::UnitX(), 0, 0},
                                         {JointPrimitive::Kind::translation, Vec3::UnitY(), 1, 1},
                                         {JointPrimitive::Kind::rotation, Vec3::UnitZ(), 2, 2}};
    };
    return t;
  }();
  return t;
}

}  // namespace kanegen
