// Revolute joint: one rotation about `axis` (dynamics.md joint table).
#include "model/joints/joint_types.hpp"

namespace kanegen {

const JointTraits& revolute_traits() {
  static const JointTraits t = [] {
    JointTraits t;
    t.type = JointType::revolute;
    t.name = "revolute";
    t.coordinates = {"angle"};
    t.speeds = {"angle_rate"};
    t.units = {"rad"};
    t.springs = 1;
    t.axes = JointTraits::Axes::one;
    t.prescribable = true;
    t.primitives = [](const Joint& j) { return std::vector<JointPrimitive>{{JointPrimitive::Kind::rotation, j.axis_J, 0, 0}}; };
    return t;
  }();
  return t;
}

}  // namespace kanegen
