#include "engine/initial_orbit.hpp"

#include "dynamics/sensors.hpp"

namespace kanegen {

void place_on_orbit(Model& model, int root, const InitialOrbit& orbit) {
  const Body& b = model.bodies[root];
  const OrbitState target = state_from_elements(model.central->mu, orbit.elements);
  const int q = b.q_joint, u = b.u_joint;  // free joint: x y z qw qx qy qz; vx vy vz wx wy wz
  const Mat3& R_NJ = b.joint.R_PJ;
  if (orbit.lvlh) {
    const Mat3 R_NB = lvlh_frame(target) * orbit.R_LB;
    const Eigen::Quaterniond Q(Mat3(R_NJ.transpose() * R_NB));
    model.q0.segment<4>(q + 3) << Q.w(), Q.x(), Q.y(), Q.z();
    model.u0.segment<3>(u + 3) = R_NB.transpose() * lvlh_rate_N(target) + orbit.rate_offset_B;
  }
  model.q0.segment<3>(q).setZero();
  model.u0.segment<3>(u).setZero();
  const OrbitState c = system_centre_of_mass(model, 0.0, model.q0, model.u0);
  // a shift of the root moves every element alike: R_NJ dx in N; a root velocity adds R_NB dv to every element
  const Eigen::Vector4d qq = model.q0.segment<4>(q + 3);
  const Mat3 R_NB = R_NJ * Eigen::Quaterniond(qq(0), qq(1), qq(2), qq(3)).normalized().toRotationMatrix();
  model.q0.segment<3>(q) = R_NJ.transpose() * (target.r_N - c.r_N);
  model.u0.segment<3>(u) = R_NB.transpose() * (target.v_N - c.v_N);
}

}  // namespace kanegen
