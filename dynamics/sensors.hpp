// The named outputs y (model/inputs_outputs.hpp) from the generic engine's
// workspace. Requires compute_kinematics, compute_body_terms and
// compute_reactions with the state's u_dot (which leave each body's
// accelerations z_dot and reaction wrench_B in the workspace).
#pragma once

#include "dynamics/central_gravity.hpp"

#include <Eigen/Geometry>
#include <algorithm>

#include "dynamics/body_terms.hpp"
#include "dynamics/invariants.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/workspace.hpp"
#include "model/orbit.hpp"
#include "model/model.hpp"

namespace kanegen {

/// Quaternion [w, x, y, z] of a rotation matrix, with w >= 0 (the sign
/// convention of the attitude output).
inline Eigen::Vector4d attitude_quaternion(const Mat3& R) {
  Eigen::Quaterniond Q(R);
  Q.normalize();
  Eigen::Vector4d v(Q.w(), Q.x(), Q.y(), Q.z());
  return v(0) < 0 ? Eigen::Vector4d(-v) : v;
}

/// The system's centre of mass and its velocity, N components (what the
/// orbit-frame sensors read), from the workspace's kinematics and body terms.
inline OrbitState system_centre_of_mass(const Model& model, Workspace<double>& ws) {  // ws's Mz: scratch
  double mass = 0.0;
  Vec3 S = Vec3::Zero();
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const BodyWorkspace<double>& s = ws.body[i];
    mass += model.bodies[i].total_mass;
    S += model.bodies[i].total_mass * s.r_NO_N + s.R_NB * s.S_B;
  }
  return {S / mass, compute_momentum(model, ws).p_N / mass};
}

/// The same at a state (q, u) at time t, from a workspace of its own.
inline OrbitState system_centre_of_mass(const Model& model, double t, const VecX& q, const VecX& u) {
  Workspace<double> ws(model);
  compute_kinematics(model, ws, t, q, u);
  compute_body_terms(model, ws);
  return system_centre_of_mass(model, ws);
}

template <class VecY>
void compute_sensor_outputs(const Model& model, Workspace<double>& ws, VecY& y) {
  const bool orbit = std::any_of(model.sensors.begin(), model.sensors.end(),
                                 [](const Sensor& sn) { return orbit_sensor(sn.type); });
  const OrbitState c = orbit ? system_centre_of_mass(model, ws) : OrbitState{};
  for (const Sensor& sn : model.sensors) {
    switch (sn.type) {  // the whole system's
      case SensorType::com_position: y.template segment<3>(sn.offset) = c.r_N; continue;
      case SensorType::com_velocity: y.template segment<3>(sn.offset) = c.v_N; continue;
      case SensorType::orbit_elements:
        y.template segment<6>(sn.offset) = osculating_elements(model.central->mu, c);
        continue;
      default: break;
    }
    const BodyWorkspace<double>& s = ws.body[sn.body];
    const Body& b = model.bodies[sn.body];
    const Vec3& p = sn.point_B;
    const Mat3 R_XB = sn.R_BX.transpose();
    const Vec3 w_B = s.w_B;
    const Vec3 a_O_B = s.z_dot.head<3>(), alpha_B = s.z_dot.segment<3>(3);
    Eigen::Matrix<double, 6, 1> v6;
    switch (sn.type) {
      case SensorType::angular_velocity: y.template segment<3>(sn.offset) = R_XB * w_B; break;
      case SensorType::attitude_lvlh: y.template segment<7>(sn.offset) = attitude_lvlh(c, s.R_NB * sn.R_BX); break;
      case SensorType::angular_velocity_lvlh:
        y.template segment<3>(sn.offset) = angular_velocity_lvlh(c, s.R_NB * sn.R_BX, R_XB * w_B);
        break;
      case SensorType::attitude: y.template segment<4>(sn.offset) = attitude_quaternion(s.R_NB * sn.R_BX); break;
      case SensorType::position: y.template segment<3>(sn.offset) = s.r_NO_N + s.R_NB * p; break;
      case SensorType::velocity: y.template segment<3>(sn.offset) = s.R_NB * (s.v_O_B + w_B.cross(p)); break;
      case SensorType::acceleration:
      case SensorType::specific_force: {
        Vec3 a_B = a_O_B + alpha_B.cross(p) + w_B.cross(w_B.cross(p));
        if (sn.type == SensorType::specific_force)
          a_B -= s.R_NB.transpose() *
                 (model.central ? central_field_at<double>(*model.central, Vec3(s.r_NO_N + s.R_NB * p)) : model.g_N);
        y.template segment<3>(sn.offset) = R_XB * a_B;
        break;
      }
      case SensorType::reaction:
        v6 << R_XB * s.wrench_B.head<3>(), R_XB * s.wrench_B.tail<3>();
        y.template segment<6>(sn.offset) = v6;
        break;
      case SensorType::deflection: {
        const FlexibleData& f = *b.flex;
        const int k = sn.node;
        Vec3 d = f.Phi.middleRows(3 * k, 3) * s.eta;
        if (f.has_second_order(k))
          for (int a = 0; a < 3; ++a)
            if (f.Gamma[k][a].size()) d(a) += 0.5 * s.eta.dot(f.Gamma[k][a] * s.eta);
        y.template segment<3>(sn.offset) = R_XB * d;
        break;
      }
      default: break;  // the system's, above
    }
  }
}

}  // namespace kanegen
