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
    case SensorType::attitude_lvlh: return "attitude_lvlh";
    case SensorType::angular_velocity_lvlh: return "angular_velocity_lvlh";
    case SensorType::com_position: return "com_position";
    case SensorType::com_velocity: return "com_velocity";
    case SensorType::orbit_elements: return "orbit_elements";
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
    case SensorType::attitude_lvlh:
      return {s.name + ".qw", s.name + ".qx",    s.name + ".qy", s.name + ".qz",
              s.name + ".roll", s.name + ".pitch", s.name + ".yaw"};
    case SensorType::orbit_elements:
      return {s.name + ".a", s.name + ".e", s.name + ".i", s.name + ".raan", s.name + ".argp", s.name + ".nu"};
    default: return {s.name + ".x", s.name + ".y", s.name + ".z"};
  }
}

}  // namespace kanegen
