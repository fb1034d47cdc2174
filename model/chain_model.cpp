#include "model/chain_model.hpp"

#include <string>

namespace kanegen {

Model make_chain_model(int n) {
  Model m;
  m.name = "chain" + std::to_string(n);
  m.description = "programmatic spatial pin chain";
  m.source_path = "<chain>";
  m.g_N = Vec3(0, 0, -9.81);
  const Vec3 axes[3] = {Vec3::UnitZ(), Vec3::UnitY(), Vec3::UnitX()};
  for (int i = 0; i < n; ++i) {
    Body b;
    b.name = "link" + std::to_string(i + 1);
    b.parent = i - 1;
    b.joint.type = JointType::revolute;
    b.joint.axis_J = axes[i % 3];
    b.joint.p_PJ = i == 0 ? Vec3::Zero() : Vec3(1.0, 0, 0);
    b.rigid.mass = 1.0 + 0.1 * i;
    b.rigid.com_B = Vec3(0.5, 0, 0);
    const double ml2 = b.rigid.mass / 12.0;
    b.rigid.I_c_B = Vec3(0.001, ml2, ml2).asDiagonal();
    m.bodies.push_back(b);
  }
  finalize_model(m);
  m.q0 = VecX::Constant(m.nq, 0.1);
  return m;
}

}  // namespace kanegen
