// Cylindrical joint: rotation about `axis` and translation along it
// (coordinates angle, disp).
#include "model/joints/joint_types.hpp"

namespace kanegen {

const JointTraits& cylindrical_traits() {
  static const JointTraits t = [] {
    JointTraits t;
    t.type = JointType::cylindrical;
    t.name = "cylindrical";
    t.coordinates = {"angle", "disp"};
    t.speeds = {"angle_rate", "disp_rate"};
    t.units = {"rad", "m"};
    t.springs = 2;
    t.axes = JointTraits::Axes::one;
    t.primitives = [](const Joint& j) {
      return std::vector<JointPrimitive>{{JointPrimitive::Kind::rotation, j.axis_J, 0, 0},
                                         {JointPrimitive::Kind::translation, j.axis_J, 1, 1}};
    };
    return t;
  }();
  return t;
}

}  // namespace kanegen
