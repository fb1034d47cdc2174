#include "sim/motion_about_com.hpp"

#include <Eigen/Geometry>

namespace kanegen {

namespace {

/// R_NB of a free root body: R_PJ (P = N) times its quaternion's rotation.
Mat3 root_R_NB(const Body& b, const VecX& q) {
  const auto Q = q.segment<4>(b.q_joint + 3);
  return b.joint.R_PJ * Eigen::Quaterniond(Q(0), Q(1), Q(2), Q(3)).normalized().toRotationMatrix();
}

}  // namespace

bool all_roots_free(const Model& model) {
  bool any = false;
  for (const Body& b : model.bodies)
    if (b.parent < 0) {
      if (b.joint.type != JointType::free) return false;
      any = true;
    }
  return any;
}

std::optional<MotionAboutCentreOfMass> motion_about_centre_of_mass(Engine& engine, double t, const VecX& q,
                                                                   const VecX& u) {
  const Model& model = engine.model();
  if (!all_roots_free(model)) return std::nullopt;
  MotionAboutCentreOfMass m;
  // the mass: every body translating at unit velocity along N's x carries p = M e_x
  VecX u_unit = VecX::Zero(model.nu);
  for (const Body& b : model.bodies)
    if (b.parent < 0) u_unit.segment<3>(b.u_joint) = root_R_NB(b, q).transpose() * Vec3::UnitX();
  m.mass = engine.momentum(t, q, u_unit).p_N.x();
  if (!(m.mass > 0.0)) return std::nullopt;
  m.v_c_N = engine.momentum(t, q, u).p_N / m.mass;
  // moved near N's origin and boosted to the centre of mass's frame
  VecX q_c = q, u_c = u;
  std::optional<Vec3> d_ref;
  for (const Body& b : model.bodies) {
    if (b.parent >= 0) continue;
    const Mat3& R_PJ = b.joint.R_PJ;
    if (!d_ref) d_ref = b.joint.p_PJ + R_PJ * q.segment<3>(b.q_joint);
    q_c.segment<3>(b.q_joint) -= R_PJ.transpose() * *d_ref;
    u_c.segment<3>(b.u_joint) -= root_R_NB(b, q).transpose() * m.v_c_N;
  }
  m.T_c = engine.energy(t, q_c, u_c).T;
  m.H_c_N = engine.momentum(t, q_c, u_c).H_N;  // about d_ref in a frame where p = 0: about the centre of mass
  return m;
}

}  // namespace kanegen
