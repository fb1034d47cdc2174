// Prismatic joint: one translation along `axis` (dynamics.md joint table).
#include "model/joints/joint_types.hpp"

namespace kanegen {

const JointTraits& prismatic_traits() {
  static const JointTraits t = [] {
    JointTraits t;
    t.type = JointType::prismatic;
    t.name = "prismatic";
    t.coordinates = {"disp"};
    t.speeds = {"disp_rate"};
    t.units = {"m"};
    t.springs = 1;
    t.axes = JointTraits::Axes::one;
    t.prescribable = true;
    t.primitives = [](const Joint& j) { return std::vector<JointPrimitive>{{JointPrimitive::Kind::translation, j.axis_J, 0, 0}}; };
    return t;
  }();
  return t;
}

}  // namespace kanegen
