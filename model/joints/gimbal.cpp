// Gimbal: three body-fixed rotations Rot(a1, angle1) Rot(a2, angle2)
// Rot(a3, angle3) (`axes:` or `sequence: zyx`, default xyz). In gimbal lock
// where its three rotation columns are linearly dependent (dynamics.md).
#include "model/joints/joint_types.hpp"

namespace kanegen {

const JointTraits& gimbal_traits() {
  static const JointTraits t = [] {
    JointTraits t;
    t.type = JointType::gimbal;
    t.name = "gimbal";
    t.coordinates = {"angle1", "angle2", "angle3"};
    t.speeds = {"angle1_rate", "angle2_rate", "angle3_rate"};
    t.units = {"rad", "rad", "rad"};
    t.springs = 3;
    t.axes = JointTraits::Axes::list;
    t.n_axes = 3;
    t.default_axes = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
    t.sequence = true;
    t.can_lock_up = true;
    t.primitives = [](const Joint& j) {
      return std::vector<JointPrimitive>{{JointPrimitive::Kind::rotation, j.axes_J[0], 0, 0},
                                         {JointPrimitive::Kind::rotation, j.axes_J[1], 1, 1},
                                         {JointPrimitive::Kind::rotation, j.axes_J[2], 2, 2}};
    };
    return t;
  }();
  return t;
}

}  // namespace kanegen
