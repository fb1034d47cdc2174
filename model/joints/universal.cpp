// Universal (Hooke) joint: Rot(a1, angle1) then Rot(a2, angle2), a2 in the
// frame turned by the first rotation (default axes x then y).
#include "model/joints/joint_types.hpp"

namespace kanegen {

const JointTraits& universal_traits() {
  static const JointTraits t = [] {
    JointTraits t;
    t.type = JointType::universal;
    t.name = "universal";
    t.coordinates = {"angle1", "angle2"};
    t.speeds = {"angle1_rate", "angle2_rate"};
    t.units = {"rad", "rad"};
    t.springs = 2;
    t.axes = JointTraits::Axes::list;
    t.n_axes = 2;
    t.default_axes = {Vec3::UnitX(), Vec3::UnitY()};
    t.primitives = [](const Joint& j) {
      return std::vector<JointPrimitive>{{JointPrimitive::Kind::rotation, j.axes_J[0], 0, 0},
                                         {JointPrimitive::Kind::rotation, j.axes_J[1], 1, 1}};
    };
    return t;
  }();
  return t;
}

}  // namespace kanegen
