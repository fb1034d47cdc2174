// Named inputs (actuators, disturbances) and named outputs (sensors) of a
// model: the `inputs:` list and the sensor entries of `outputs:` (docs/gnc.md).
//
// Inputs form one vector w of scalars, in declaration order: a thruster or a
// joint torque is one scalar, a force or torque vector three (name.x, .y, .z).
// Each acts on a body as a wrench at a body point; its generalized forces are
// the partial velocities dotted with it (Kane's generalized active forces):
// the engines add the wrench to the body's applied forces before the inward
// pass, so forcing, u_dot, the reactions and the Jacobians all include it.
//
// Outputs form one vector y, in declaration order (a quaternion is four
// entries name.qw..qz, a reaction six, the others three).
//
// Frames: every point, direction and output axis is given in the model body's
// frame B. The generator re-chooses frames and merges fixed bodies
// (codegen/joint_frames.hpp, merge_fixed.hpp); it then carries each port to the
// body and frame it ends up in, which is why a port stores its own axes R_BX
// (the port's axes in its body's frame: the identity as loaded).
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

namespace kanegen {

enum class InputType {
  thruster,      ///< scalar force along a body-fixed direction at a body point
  force,         ///< 3-vector force at a body point, in body or inertial axes
  torque,        ///< 3-vector torque on a body, in body or inertial axes
  joint_torque,  ///< generalized forces on a joint's speeds: one (`coordinate:`) or all of them
};

enum class Axes { body, inertial };

struct Input {
  std::string name;
  int line = 0;                                  ///< line in the model file
  InputType type = InputType::thruster;
  int body = -1;                                 ///< body the wrench acts on (joint_torque: the joint's body)
  Eigen::Vector3d point_B = Eigen::Vector3d::Zero();      ///< point of application, body components
  int node = -1;  ///< force on a flexible body: applied at this node (index), displaced with it; else -1
  Eigen::Vector3d direction_B = Eigen::Vector3d::UnitX(); ///< thruster: unit direction, body components
  Axes axes = Axes::body;                        ///< force, torque: axes of the three components
  Eigen::Matrix3d R_BX = Eigen::Matrix3d::Identity();     ///< body-axes components: x_B = R_BX x_input
  int offset = 0;                                ///< first entry in w
  /// joint_torque: the joint's speeds it drives, speed .. speed + speeds - 1
  /// (within the joint); names of its entries when more than one.
  int speed = 0;
  int speeds = 1;
  std::vector<std::string> speed_names;
  int size() const {
    return type == InputType::force || type == InputType::torque ? 3 : type == InputType::joint_torque ? speeds : 1;
  }
};

enum class SensorType {
  angular_velocity,  ///< w of the body, body axes (rad/s)
  attitude,          ///< quaternion [qw, qx, qy, qz] of R_NB (qw >= 0)
  position,          ///< inertial position of a body point, N components
  velocity,          ///< inertial velocity of a body point, N components
  acceleration,      ///< inertial acceleration of a body point, body axes
  specific_force,    ///< acceleration minus gravity at a body point, body axes (an accelerometer)
  reaction,          ///< the joint's reaction on the body [force; torque about O_B], body axes
  deflection,        ///< elastic displacement of a node of a flexible body, body axes
  // orbit-frame sensors (a central field; templates/orbit_frame.inc, docs/gnc.md):
  attitude_lvlh,          ///< quaternion of R_LB (qw >= 0) and its rotation vector: roll, pitch, yaw
  angular_velocity_lvlh,  ///< w of the body relative to the orbit frame L, body axes (rad/s)
  com_position,           ///< the system's centre of mass from the central body, N components (no body)
  com_velocity,           ///< its velocity, N components (no body)
  orbit_elements,         ///< the centre of mass's osculating a, e, i, raan, argp, nu (no body)
};

/// Whether a sensor reads the whole system (no body of its own).
inline bool system_sensor(enum SensorType t) {
  return t == SensorType::com_position || t == SensorType::com_velocity || t == SensorType::orbit_elements;
}
/// Whether a sensor is relative to the central body (needs gravity: central).
inline bool central_sensor(enum SensorType t) {
  return t == SensorType::orbit_elements || t == SensorType::attitude_lvlh || t == SensorType::angular_velocity_lvlh;
}
/// Whether a sensor needs the system's centre of mass (the orbit-frame sensors).
inline bool orbit_sensor(enum SensorType t) {
  return system_sensor(t) || t == SensorType::attitude_lvlh || t == SensorType::angular_velocity_lvlh;
}

struct Sensor {
  std::string name;
  int line = 0;
  SensorType type = SensorType::angular_velocity;
  int body = -1;  ///< -1: a system sensor (system_sensor())
  Eigen::Vector3d point_B = Eigen::Vector3d::Zero();   ///< point sensors: the point, body components
  int node = -1;                                       ///< deflection: index into the body's nodes
  Eigen::Matrix3d R_BX = Eigen::Matrix3d::Identity();  ///< output axes in the body frame (see the header comment)
  int offset = 0;                                      ///< first entry in y
  int size() const {
    switch (type) {
      case SensorType::attitude: return 4;
      case SensorType::reaction: return 6;
      case SensorType::attitude_lvlh: return 7;
      case SensorType::orbit_elements: return 6;
      default: return 3;
    }
  }
};

const char* to_string(InputType t);
const char* to_string(SensorType t);
const char* to_string(Axes a);

/// Scalar names of one input's entries ("thr1"; "mtq.x", "mtq.y", "mtq.z").
std::vector<std::string> entry_names(const Input& in);
/// Scalar names of one sensor's entries ("gyro.x", ...; "att.qw", ...;
/// "hinge.fx", ..., "hinge.tz").
std::vector<std::string> entry_names(const Sensor& s);

/// Re-expresses the inputs and sensors of body `from` in the frame of body
/// `to`, whose frame sees `from`'s at origin p and axes R (x_to = p + R x_from):
/// used when the generator merges a fixed body into its parent or re-chooses
/// a body's frame (from == to).
void move_ports(std::vector<Input>& inputs, std::vector<Sensor>& sensors, int from, int to,
                const Eigen::Vector3d& p, const Eigen::Matrix3d& R);

}  // namespace kanegen
