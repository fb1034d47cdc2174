#include "model/inputs_outputs.hpp"

namespace kanegen {

const char* to_string(InputType t) {
  switch (t) {
    case InputType::thruster: return "thruster";
    case InputType::force: return "force";
    case InputType::torque: return "torque";
    case InputType::joint_torque: return "joint_torque";
  }
  return "?";
}

const char* to_string(SensorType t) {
  switch (t) {
    case SensorType::angular_velocity: return "angular_velocity";
    case SensorType::attitude: return "attitude";
    case SensorType::position: return "position";
    case SensorType::velocity: return "velocity";
    case SensorType::acceleration: return "acceleration";
    case SensorType::specific_force: return "specific_force";
    case SensorType::reaction: return "reaction";
    case SensorType::deflection: return "deflection";
  }
  return "?";
}

void move_ports(std::vector<Input>& inputs, std::vector<Sensor>& sensors, int from, int to,
                const Eigen::Vector3d& p, const Eigen::Matrix3d& R) {
  for (Input& in : inputs) {
    if (in.body != from) continue;
    in.body = to;
    in.point_B = p + R * in.point_B;
    in.direction_B = R * in.direction_B;
    in.R_BX = R * in.R_BX;
  }
  for (Sensor& s : sensors) {
    if (s.body != from) continue;
    s.body = to;
    s.point_B = p + R * s.point_B;
    s.R_BX = R * s.R_BX;
  }
}

const char* to_string(Axes a) { return a == Axes::body ? "body" : "inertial"; }

std::vector<std::string> entry_names(const Input& in) {
  if (in.size() == 1) return {in.name};
  if (in.type == InputType::joint_torque) {
    std::vector<std::string> names;
    for (const auto& s : in.speed_names) names.push_back(in.name + "." + s);
    return names;
  }
  return {in.name + ".x", in.name + ".y", in.name + ".z"};
}

std::vector<std::string> entry_names(const Sensor& s) {
  switch (s.type) {
    case SensorType::attitude: return {s.name + ".qw", s.name + ".qx", s.name + ".qy", s.name + ".qz"};
    case SensorType::reaction:
      return {s.name + ".fx", s.name + ".fy", s.name + ".fz", s.name + ".tx", s.name + ".ty", s.name + ".tz"};
    default: return {s.name + ".x", s.name + ".y", s.name + ".z"};
  }
}

}  // namespace kanegen
