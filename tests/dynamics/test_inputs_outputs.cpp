// Named inputs and outputs (docs/gnc.md) checked against physics, not only
// generated against generic: an input's generalized forces deliver exactly
// its power (f . v_P + t . w), and each sensor is consistent with the others
// along the motion (d/dt position = velocity, d/dt velocity = acceleration,
// attitude rates = angular velocity, specific force = acceleration - g).
#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "sim/crosscheck.hpp"
#include "tests/support/crosscheck_checks.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

const char* kPorts = "tests/data/good/gnc_ports.yaml";

Mat3 rotation_of(const Eigen::Vector4d& q) { return Eigen::Quaterniond(q(0), q(1), q(2), q(3)).toRotationMatrix(); }

VecX outputs(Engine& e, double t, const VecX& q, const VecX& u, const VecX& tau) {
  VecX y;
  e.outputs(t, q, u, tau, y);
  return y;
}

}  // namespace

TEST_CASE("inputs: generalized forces deliver the input's power", "[inputs][physics]") {
  // Sum_r F_r u_r over the input's share of F equals f . v_P + t . w for any
  // u: Kane's generalized active forces, checked with the velocities the
  // sensors report (velocity at the point of application, gyro, attitude).
  const std::string yaml = R"(
name: power_check
gravity: [0, 0, -9.81]
bodies:
  - {name: bus, parent: ground, joint: {type: free}, mass: 50, com: [0.02, -0.01, 0.03], inertia: [4, 5, 6, 0.1, -0.2, 0.05]}
  - {name: tracker, parent: bus, joint: {type: fixed, position: [0.3, 0.2, 0.4], rotation: {rpy: [0.3, -0.2, 0.5]}}, mass: 1.5, inertia: [0.01, 0.02, 0.015, 0, 0, 0]}
  - {name: arm, parent: tracker, joint: {type: revolute, axis: [0.6, 0, 0.8], position: [0.1, -0.1, 0.2]}, mass: 2, com: [0.3, 0.05, 0], inertia: [0.02, 0.1, 0.1, 0.01, 0, 0]}
inputs:
  - {name: thr, type: thruster, body: tracker, point: [0.5, 0.1, -0.4], direction: [0, 0.6, 0.8]}
  - {name: fin, type: force, body: arm, point: [0.4, 0.2, 0.1], axes: inertial}
  - {name: fb, type: force, body: arm, point: [0.4, 0.2, 0.1], axes: body}
  - {name: tin, type: torque, body: bus, axes: inertial}
  - {name: tb, type: torque, body: tracker, axes: body}
  - {name: motor, type: joint_torque, joint: arm}
outputs:
  - {name: v_thr, type: velocity, body: tracker, point: [0.5, 0.1, -0.4]}
  - {name: v_arm, type: velocity, body: arm, point: [0.4, 0.2, 0.1]}
  - {name: w_bus, type: angular_velocity, body: bus}
  - {name: w_trk, type: angular_velocity, body: tracker}
  - {name: w_arm, type: angular_velocity, body: arm}
  - {name: att_bus, type: attitude, body: bus}
  - {name: att_trk, type: attitude, body: tracker}
  - {name: att_arm, type: attitude, body: arm}
)";
  const Model model = load_model(test::write_temp("power_check.yaml", yaml));
  REQUIRE(model.nw == 14);
  GenericEngine generic(model);
  auto generated = test::generated_engine(model);
  for (Engine* e : {static_cast<Engine*>(&generic), static_cast<Engine*>(generated.get())}) {
    INFO(e->name());
    VecX q = model.q0, u(model.nu), tau = VecX::Zero(model.nu);
    q.segment<4>(3) = Eigen::Vector4d(0.8, 0.2, -0.4, 0.4).normalized();
    q(model.q_index("arm.angle")) = 0.7;
    for (int i = 0; i < model.nu; ++i) u(i) = 0.3 + 0.1 * i * (i % 2 ? -1 : 1);
    VecX F0, F1, y;
    e->set_inputs(VecX::Zero(model.nw));
    e->forcing(q, u, tau, F0);
    e->outputs(0.0, q, u, tau, y);
    const Vec3 v_thr = y.segment<3>(model.output_index("v_thr.x")), v_arm = y.segment<3>(model.output_index("v_arm.x"));
    const Vec3 w_bus = y.segment<3>(model.output_index("w_bus.x")), w_trk = y.segment<3>(model.output_index("w_trk.x")),
               w_arm = y.segment<3>(model.output_index("w_arm.x"));
    const Mat3 R_bus = rotation_of(y.segment<4>(model.output_index("att_bus.qw")));
    const Mat3 R_trk = rotation_of(y.segment<4>(model.output_index("att_trk.qw")));
    const Mat3 R_arm = rotation_of(y.segment<4>(model.output_index("att_arm.qw")));
    for (int k = 0; k < model.nw; ++k) {
      INFO(model.input_names[k]);
      VecX w = VecX::Zero(model.nw);
      w(k) = 1.7;
      e->set_inputs(w);
      e->forcing(q, u, tau, F1);
      const double generalized_power = (F1 - F0).dot(u);
      const std::string& n = model.input_names[k];
      const Vec3 e_k = k % 3 == 0 ? Vec3::UnitX() : k % 3 == 1 ? Vec3::UnitY() : Vec3::UnitZ();
      double power = 0;
      if (n == "thr") power = 1.7 * (R_trk * Vec3(0, 0.6, 0.8)).dot(v_thr);
      if (n.rfind("fin.", 0) == 0) power = 1.7 * Vec3::Unit(n.back() - 'x').dot(v_arm);
      if (n.rfind("fb.", 0) == 0) power = 1.7 * (R_arm * Vec3::Unit(n.back() - 'x')).dot(v_arm);
      if (n.rfind("tin.", 0) == 0) power = 1.7 * Vec3::Unit(n.back() - 'x').dot(R_bus * w_bus);
      if (n.rfind("tb.", 0) == 0) power = 1.7 * Vec3::Unit(n.back() - 'x').dot(w_trk);
      if (n == "motor") power = 1.7 * u(model.u_index("arm.angle_rate"));
      (void)e_k;
      CHECK(std::abs(generalized_power - power) <= 1e-12 * (1 + std::abs(power)));
    }
    (void)w_arm;
  }
}

TEST_CASE("outputs: sensors agree with each other along the motion", "[outputs][physics]") {
  const Model model = load_model(test::source_path(kPorts));
  GenericEngine generic(model);
  auto generated = test::generated_engine(model);
  State s = load_state(model, test::write_temp("ports_state.json", R"({"inputs": {"thr": 2.0, "mtq.x": 0.3,
     "push.y": -2.0, "twist.z": -0.3, "motor": 0.7, "tipload.z": -0.4}, "tau": {"arm.angle": 0.05}})"));
  for (Engine* e : {static_cast<Engine*>(&generic), static_cast<Engine*>(generated.get())}) {
    INFO(e->name());
    e->set_inputs(s.w);
    // central difference along the trajectory: x(t +- h) ~ x +- h x_dot (+ h^2/2 x_ddot, cancelling)
    VecX qd, ud;
    e->qdot(s.q, s.u, qd);
    e->udot(s.q, s.u, s.tau, ud);
    const double h = 1e-5;
    const VecX yp = outputs(*e, 0, s.q + h * qd, s.u + h * ud, s.tau);
    const VecX ym = outputs(*e, 0, s.q - h * qd, s.u - h * ud, s.tau);
    const VecX y = outputs(*e, 0, s.q, s.u, s.tau);
    const VecX dy = (yp - ym) / (2 * h);
    auto seg = [&](const VecX& v, const std::string& name, int n = 3) { return VecX(v.segment(model.output_index(name), n)); };
    const Mat3 R_arm = rotation_of(seg(y, "att_arm.qw", 4));
    const double tol = 1e-7;
    // position -> velocity (N components), at the same bus point
    CHECK((seg(dy, "gps.x") - seg(y, "gps_v.x")).norm() <= tol * (1 + seg(y, "gps_v.x").norm()));
    // velocity (N) -> acceleration (arm axes), at the same arm point
    const Vec3 a_N = R_arm * Vec3(seg(y, "vel_a.x"));
    CHECK((Vec3(seg(dy, "vel.x")) - a_N).norm() <= tol * (1 + a_N.norm()));
    // an accelerometer reads the acceleration minus gravity
    const Vec3 sf = Vec3(seg(y, "vel_a.x")) - R_arm.transpose() * model.g_N;
    CHECK((Vec3(seg(y, "vel_sf.x")) - sf).norm() <= 1e-12 * (1 + sf.norm()));
    // attitude -> angular velocity: q_dot = 1/2 q (x) [0; w]
    const Eigen::Vector4d att = seg(y, "att.qw", 4), datt = seg(dy, "att.qw", 4);
    const Eigen::Quaterniond Q(att(0), att(1), att(2), att(3)), dQ(datt(0), datt(1), datt(2), datt(3));
    const Eigen::Quaterniond W = Q.conjugate() * dQ;  // = [0; w/2]
    CHECK(std::abs(W.w()) <= 1e-8);
    CHECK((2.0 * W.vec() - seg(y, "gyro.x")).norm() <= 1e-8 * (1 + seg(y, "gyro.x").norm()));
  }
}

TEST_CASE("crosscheck: generated outputs and inputs agree with the generic engine", "[inputs][outputs][generated]") {
  const Model model = load_model(test::source_path(kPorts));
  GenericEngine generic(model);
  auto generated = test::generated_engine(model);
  const CrosscheckResult r = crosscheck(*generated, generic, 10, 11);
  test::check_within_tolerances(r);
  REQUIRE(r.worst.count("outputs"));
}

TEST_CASE("inputs: a force at a flexible body's node delivers its power, foreshortening included", "[inputs][physics][flexible]") {
  // The node's inertial velocity by a central difference of its position
  // r = r_O + R_NB (rho_k + deflection) along the motion (from the sensors),
  // against the generalized power of the force, both engines.
  const std::string yaml = R"(
name: node_force
bodies:
  - {name: bus, parent: ground, joint: {type: free}, mass: 30, inertia: [3, 4, 5, 0.1, 0, 0]}
  - name: boom
    parent: bus
    joint: {type: revolute, axis: [0, 0, 1], position: [0.5, 0, 0]}
    flexible:
      beam: {length: 2.0, direction: x, mass_per_length: 0.5, EI: [20.0, 30.0], elements: 6, modes: 3}
      damping_ratio: 0.01
initial:
  q: {bus.qw: 0.9, bus.qx: 0.3, bus.qy: 0.1, bus.qz: -0.3, boom.angle: 0.4, boom.eta1: 0.05, boom.eta2: -0.03, boom.eta3: 0.02}
  u: {bus.vx: 0.2, bus.wx: 0.3, bus.wy: -0.2, bus.wz: 0.5, boom.angle: 0.7, boom.eta1: 0.4, boom.eta2: -0.3, boom.eta3: 0.2}
inputs:
  - {name: f_body, type: force, body: boom, node: 7, axes: body}
  - {name: f_inertial, type: force, body: boom, node: 5, axes: inertial}
outputs:
  - {name: origin, type: position, body: boom}
  - {name: att, type: attitude, body: boom}
  - {name: d7, type: deflection, body: boom, node: 7}
  - {name: d5, type: deflection, body: boom, node: 5}
)";
  const Model model = load_model(test::write_temp("node_force.yaml", yaml));
  const FlexibleData& fd = *model.bodies[1].flex;
  REQUIRE(fd.has_second_order(fd.node_index(7)));  // the built-in beam carries foreshortening
  GenericEngine generic(model);
  auto generated = test::generated_engine(model);
  for (Engine* e : {static_cast<Engine*>(&generic), static_cast<Engine*>(generated.get())}) {
    INFO(e->name());
    const VecX& q = model.q0;
    const VecX& u = model.u0;
    const VecX tau = VecX::Zero(model.nu);
    e->set_inputs(VecX::Zero(model.nw));
    VecX qd, ud, F0, F1;
    e->qdot(q, u, qd);
    e->udot(q, u, tau, ud);
    e->forcing(q, u, tau, F0);
    // the node's inertial position from the outputs
    auto node_position = [&](const VecX& qq, const VecX& uu, int id, const std::string& d) {
      VecX y;
      e->outputs(0.0, qq, uu, tau, y);
      const Eigen::Vector4d a = y.segment<4>(model.output_index("att.qw"));
      const Mat3 R = Eigen::Quaterniond(a(0), a(1), a(2), a(3)).toRotationMatrix();
      const Vec3 rho = fd.nodes[fd.node_index(id)].rho_B;
      return Vec3(y.segment<3>(model.output_index("origin.x")) + R * (rho + y.segment<3>(model.output_index(d + ".x"))));
    };
    const double h = 1e-6;
    for (const auto& [input, id, d] : {std::tuple{"f_body", 7, "d7"}, std::tuple{"f_inertial", 5, "d5"}}) {
      INFO(input);
      const Vec3 v_N = (node_position(q + h * qd, u + h * ud, id, d) - node_position(q - h * qd, u - h * ud, id, d)) / (2 * h);
      e->set_inputs(VecX::Zero(model.nw));
      VecX y;
      e->outputs(0.0, q, u, tau, y);
      const Eigen::Vector4d a = y.segment<4>(model.output_index("att.qw"));
      const Mat3 R = Eigen::Quaterniond(a(0), a(1), a(2), a(3)).toRotationMatrix();
      const Vec3 f(1.3, -0.7, 2.1);
      VecX w = VecX::Zero(model.nw);
      w.segment<3>(model.input_index(std::string(input) + ".x")) = f;
      e->set_inputs(w);
      e->forcing(q, u, tau, F1);
      const Vec3 f_N = std::string(input) == "f_body" ? Vec3(R * f) : f;
      const double power = f_N.dot(v_N), generalized = (F1 - F0).dot(u);
      CHECK(std::abs(generalized - power) <= 1e-7 * (1 + std::abs(power)));
    }
  }
}
