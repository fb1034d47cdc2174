#include "codegen/merge_fixed.hpp"

namespace kanegen::codegen {

namespace {

Mat3 point_inertia(double m, const Vec3& r) { return m * (r.squaredNorm() * Mat3::Identity() - r * r.transpose()); }

bool mergeable(const Body& b) { return b.joint.type == JointType::fixed && b.joint.node < 0 && !b.flex; }

/// A body whose rigid part or joint placement holds runtime parameters keeps
/// its own terms (its parameters are given in its own frame), and its parent
/// keeps its own when its rigid part holds some.
bool has_parameters(const Model& m, int j, bool placement) {
  for (const RuntimeParameter& p : m.parameters)
    if (p.body == j && (p.kind == ParameterKind::mass || p.kind == ParameterKind::com || p.kind == ParameterKind::inertia ||
                        (placement && (p.kind == ParameterKind::position || p.kind == ParameterKind::misalignment))))
      return true;
  return false;
}

/// Adds rigid part `c`, located by (p, R) in the frame of `a`, to `a`.
void add_rigid(RigidPart& a, const RigidPart& c, const Vec3& p, const Mat3& R) {
  const Vec3 com_c = p + R * c.com_B;
  const Mat3 J_a = a.I_c_B + point_inertia(a.mass, a.com_B);
  const Mat3 J_c = R * c.I_c_B * R.transpose() + point_inertia(c.mass, com_c);
  const double m = a.mass + c.mass;
  const Vec3 com = m > 0 ? Vec3((a.mass * a.com_B + c.mass * com_c) / m) : Vec3::Zero();
  a.mass = m;
  a.com_B = com;
  a.I_c_B = J_a + J_c - point_inertia(m, com);
}

}  // namespace

Model merge_fixed_bodies(const Model& in) {
  Model m = in;
  bool changed = true;
  while (changed) {
    changed = false;
    for (std::size_t j = 0; j < m.bodies.size(); ++j) {
      if (!mergeable(m.bodies[j])) continue;
      const Body fixed = m.bodies[j];
      const int p = fixed.parent;
      if (p < 0) continue;  // fixed to ground: kept (it never moves; costs nothing)
      if (has_parameters(m, static_cast<int>(j), true) || has_parameters(m, p, false)) continue;
      add_rigid(m.bodies[p].rigid, fixed.rigid, fixed.joint.p_PJ, fixed.joint.R_PJ);
      move_ports(m.inputs, m.sensors, static_cast<int>(j), p, fixed.joint.p_PJ, fixed.joint.R_PJ);
      for (Body& c : m.bodies) {
        if (c.parent != static_cast<int>(j)) continue;
        c.parent = p;
        c.joint.p_PJ = fixed.joint.p_PJ + fixed.joint.R_PJ * c.joint.p_PJ;
        c.joint.R_PJ = fixed.joint.R_PJ * c.joint.R_PJ;
      }
      m.bodies.erase(m.bodies.begin() + static_cast<long>(j));
      for (Body& c : m.bodies)
        if (c.parent > static_cast<int>(j)) --c.parent;
      for (Input& in : m.inputs)
        if (in.body > static_cast<int>(j)) --in.body;
      for (Sensor& s : m.sensors)
        if (s.body > static_cast<int>(j)) --s.body;
      for (RuntimeParameter& rp : m.parameters)
        if (rp.body > static_cast<int>(j)) --rp.body;
      changed = true;
      break;
    }
  }
  if (m.bodies.size() != in.bodies.size()) {
    const VecX q0 = in.q0, u0 = in.u0;
    finalize_model(m);
    m.q0 = q0;
    m.u0 = u0;
  }
  return m;
}

}  // namespace kanegen::codegen
