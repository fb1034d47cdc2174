#include "sim/mass_properties.hpp"

#include <optional>

#include <Eigen/Eigenvalues>

#include "dynamics/body_terms.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/workspace.hpp"

namespace kanegen {

namespace {

/// Where the system is, in N: the origin of its first free root body (O_B = p_PJ + R_PJ x), or N's origin.
/// Every free root is moved by -d_ref before the kinematics, so that positions of the order of an orbit's
/// radius never enter the sums (no cancellation: the inertia about the centre of mass is the same to
/// round-off at any distance from N's origin); the centre of mass is put back at the end.
Vec3 move_free_roots_near_origin(const Model& model, State& s) {
  std::optional<Vec3> d_ref;
  for (const Body& b : model.bodies) {
    if (b.parent >= 0 || b.joint.type != JointType::free) continue;
    const Mat3& R_PJ = b.joint.R_PJ;
    if (!d_ref) d_ref = b.joint.p_PJ + R_PJ * s.q.segment<3>(b.q_joint);
    s.q.segment<3>(b.q_joint) -= R_PJ.transpose() * *d_ref;
  }
  return d_ref.value_or(Vec3::Zero());
}

}  // namespace

SystemMassProperties system_mass_properties(const Model& model, const State& state) {
  State moved = state;
  const Vec3 d_ref = move_free_roots_near_origin(model, moved);
  Workspace<double> ws(model);
  compute_kinematics(model, ws, moved.t, moved.q, moved.u);
  compute_body_terms(model, ws);
  SystemMassProperties p;
  Vec3 S_N = Vec3::Zero();  // first moment about the reference point d_ref
  Mat3 J_N = Mat3::Zero();  // inertia about it
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const BodyWorkspace<double>& s = ws.body[i];
    const double m = model.bodies[i].total_mass;
    const Vec3 S_O_N = s.R_NB * s.S_B;                                   // first moment about O_B
    const Mat3 J_O_N = s.R_NB * s.M_body.block<3, 3>(3, 3) * s.R_NB.transpose();  // inertia about O_B
    const Vec3& d = s.r_NO_N;                                            // O_B from the reference point
    // about the reference point (r = d + x): J_O + m(|d|^2 I - d d^T) + 2 (d.S) I - d S^T - S d^T
    J_N += J_O_N + m * (d.squaredNorm() * Mat3::Identity() - d * d.transpose()) +
           2.0 * d.dot(S_O_N) * Mat3::Identity() - d * S_O_N.transpose() - S_O_N * d.transpose();
    S_N += m * d + S_O_N;
    p.mass += m;
  }
  const Vec3 c = p.mass > 0.0 ? Vec3(S_N / p.mass) : Vec3::Zero();  // from the reference point
  p.com_N = d_ref + c;
  p.J_com_N = J_N - p.mass * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
  const Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (p.J_com_N + p.J_com_N.transpose()));
  p.principal_moments = es.eigenvalues();
  p.principal_axes_N = es.eigenvectors();
  if (p.principal_axes_N.determinant() < 0) p.principal_axes_N.col(2) *= -1.0;
  return p;
}

}  // namespace kanegen
