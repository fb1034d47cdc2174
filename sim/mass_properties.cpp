#include "sim/mass_properties.hpp"

#include <Eigen/Eigenvalues>

#include "dynamics/body_terms.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/workspace.hpp"

namespace kanegen {

SystemMassProperties system_mass_properties(const Model& model, const State& state) {
  Workspace<double> ws(model);
  compute_kinematics(model, ws, state.t, state.q, state.u);
  compute_body_terms(model, ws);
  SystemMassProperties p;
  Vec3 S_N = Vec3::Zero();  // first moment about N's origin
  Mat3 J_N = Mat3::Zero();  // inertia about N's origin
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const BodyWorkspace<double>& s = ws.body[i];
    const double m = model.bodies[i].total_mass;
    const Vec3 S_O_N = s.R_NB * s.S_B;                                   // first moment about O_B
    const Mat3 J_O_N = s.R_NB * s.M_body.block<3, 3>(3, 3) * s.R_NB.transpose();  // inertia about O_B
    const Vec3& d = s.r_NO_N;                                            // O_B from N's origin
    // about N's origin (r = d + x): J_O + m(|d|^2 I - d d^T) + 2 (d.S) I - d S^T - S d^T
    J_N += J_O_N + m * (d.squaredNorm() * Mat3::Identity() - d * d.transpose()) +
           2.0 * d.dot(S_O_N) * Mat3::Identity() - d * S_O_N.transpose() - S_O_N * d.transpose();
    S_N += m * d + S_O_N;
    p.mass += m;
  }
  if (p.mass > 0.0) p.com_N = S_N / p.mass;
  const Vec3& c = p.com_N;
  p.J_com_N = J_N - p.mass * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
  const Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (p.J_com_N + p.J_com_N.transpose()));
  p.principal_moments = es.eigenvalues();
  p.principal_axes_N = es.eigenvectors();
  if (p.principal_axes_N.determinant() < 0) p.principal_axes_N.col(2) *= -1.0;
  return p;
}

}  // namespace kanegen
