// Fixed joint: no motion; B is the joint frame.
#include "model/joints/joint_types.hpp"

namespace kanegen {

const JointTraits& fixed_traits() {
  static const JointTraits t = [] {
    JointTraits t;
    t.type = JointType::fixed;
    t.name = "fixed";
    t.primitives = [](const Joint&) { return std::vector<JointPrimitive>{}; };
    return t;
  }();
  return t;
}

}  // namespace kanegen
