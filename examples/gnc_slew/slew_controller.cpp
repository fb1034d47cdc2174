// A PD attitude controller on reaction-wheel torques for
// models/gnc/slew_spacecraft.yaml, as flight software runs it: sampled at
// 10 Hz, reading the star tracker (attitude quaternion) and the gyro (body
// rate), commanding the three wheel motors, held until the next sample.
// Built into the simulator by
//     kanegen_add_model(slew_sim slew_spacecraft.yaml CONTROLLER slew_controller.cpp)
// (docs/gnc.md). The slew: 30 deg about the bus z axis from rest.
#include <Eigen/Geometry>
#include <algorithm>
#include <stdexcept>

#include "sim/controller.hpp"

namespace {

// The bus with its arrays about its z axis (rigid, wheels included): 300 +
// 2 x 4 kg/m (6^3 - 1^3)/3 m^3 ~ 875 kg m^2; about x ~ 995 (arrays at 1..6 m
// along y count about x too), about y ~ 380.
const Eigen::Vector3d kInertia(995.0, 380.0, 875.0);
constexpr double kBandwidth = 0.05;   // rad/s: a decade below the arrays' first mode (1.1 rad/s)
constexpr double kDamping = 0.9;
constexpr double kMaxTorque = 0.3;    // N m per wheel motor
constexpr double kSlewDeg = 30.0;

}  // namespace

kanegen::Controller kanegen_controller(const kanegen::Model& model) {
  const int att = model.output_index("star_tracker.qw"), gyro = model.output_index("gyro.x");
  const int motor = model.input_index("motor_x");
  if (att < 0 || gyro < 0 || motor < 0 || model.input_index("motor_z") != motor + 2)
    throw std::runtime_error("slew controller: the model lacks star_tracker, gyro or motor_x..motor_z");
  const double half = 0.5 * kSlewDeg * M_PI / 180.0;
  const Eigen::Quaterniond target(std::cos(half), 0.0, 0.0, std::sin(half));
  const Eigen::Vector3d Kp = kInertia * kBandwidth * kBandwidth;
  const Eigen::Vector3d Kd = kInertia * (2.0 * kDamping * kBandwidth);
  kanegen::Controller c;
  c.period = 0.1;
  c.law = [=](double, const kanegen::VecX&, const kanegen::VecX&, const kanegen::VecX& y, kanegen::VecX& w) {
    const Eigen::Quaterniond q(y(att), y(att + 1), y(att + 2), y(att + 3));
    Eigen::Quaterniond e = target.conjugate() * q;  // the bus relative to the target, body axes
    if (e.w() < 0) e.coeffs() = -e.coeffs();
    const Eigen::Vector3d rate = y.segment<3>(gyro);
    // torque on the bus; the motors apply its opposite to the wheels' spin axes
    Eigen::Vector3d torque = -(Kp.cwiseProduct(2.0 * e.vec()) + Kd.cwiseProduct(rate));
    const double peak = torque.cwiseAbs().maxCoeff();
    if (peak > kMaxTorque) torque *= kMaxTorque / peak;  // saturate, keeping the direction
    w.segment<3>(motor) = -torque;
  };
  return c;
}
