// Central gravity in the generated code (issue 22): a flexible spacecraft
// with every kind of mass element (rigid parts, a fixed child kept apart,
// plain nodes, nodes with foreshortening, nodes with rotary inertia) on
// orbit, with J2, mu and J2 as runtime parameters: the generated u-dot,
// energy, reactions and outputs against the generic engine, and its
// gravity-gradient torque against 3 mu / r^3 (r^ x I r^) on its own scale
// (it is 1e-10 of the orbital force, so a relative check of F alone would
// not see it).
#include <catch2/catch.hpp>

#include <random>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/parameters.hpp"
#include "sim/crosscheck.hpp"
#include "tests/support/crosscheck_checks.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

const char* kPanel = R"(nodes:
  - {id: 1, position: [0, 0, 0], mass: 0.0}
  - {id: 2, position: [0, 0.6, 0], mass: 1.5, inertia: [0.02, 0.004, 0.02, 0.001, 0, 0]}
  - {id: 3, position: [0.05, 1.2, 0.02], mass: 1.2, inertia: [0.015, 0.003, 0.016, 0, 0.0005, 0]}
modes:
  - frequency: 1.7
    shapes: {1: [0, 0, 0, 0, 0, 0], 2: [0, 0, 0.3, 0.5, 0, 0], 3: [0.01, 0, 0.9, 0.7, 0, 0.02]}
  - frequency: 2.9
    shapes: {1: [0, 0, 0, 0, 0, 0], 2: [0.25, 0, 0, 0, 0, -0.4], 3: [0.8, 0.02, 0, 0.03, 0, -0.6]}
mass_normalized: false
second_order:
  3: {y: [[-0.8, 0.1], [0.1, -0.6]]}
)";

std::string spacecraft(const std::string& panel_path, bool params) {
  return std::string("name: orbiting_flexible\ngravity: {central: {mu: 3.986004418e14, J2: 1.08262668e-3, radius: "
                     "6378137.0}}\n") +
         (params ? "parameters: [gravity.mu, gravity.J2]\n" : "") + R"(bodies:
  - name: bus
    parent: ground
    joint: {type: free}
    mass: 500.0
    com: [0.02, -0.01, 0.03]
    inertia: [300.0, 420.0, 250.0, 12.0, -7.0, 5.0]
  - name: camera
    parent: bus
    joint: {type: fixed, position: [0.4, 0.1, -0.6], rotation: {axis_angle: [[0, 1, 0], 0.3]}}
    mass: 20.0
    com: [0.05, 0, 0]
    inertia: [0.6, 0.9, 0.8, 0, 0.02, 0]
  - name: boom
    parent: bus
    joint: {type: revolute, axis: [0, 0, 1], position: [0.8, 0, 0], stiffness: 30.0}
    flexible:
      beam: {length: 3.0, direction: x, mass_per_length: 1.5, EI: [500.0, 400.0], elements: 5, modes: 2}
  - name: panel
    parent: bus
    joint: {type: fixed, position: [0, 0.9, 0]}
    flexible:
      modal: )" + panel_path + R"(
outputs:
  - energy
  - momentum
  - {name: imu, type: specific_force, body: bus, point: [0.3, 0.2, 0.1]}
  - {name: tip_accel, type: acceleration, body: boom, point: [3.0, 0, 0]}
  - {name: boom_root, type: reaction, joint: boom}
)";
}

}  // namespace

TEST_CASE("central gravity in the generated code: every mass element, J2, runtime mu and J2, against the generic engine",
          "[central][generator]") {
  const std::string panel = test::write_temp("cg_panel.modal.yaml", kPanel);
  for (bool params : {false, true}) {
    INFO((params ? "mu and J2 as runtime parameters" : "mu and J2 folded"));
    const Model model = load_model(test::write_temp("cg_flex.yaml", spacecraft(panel, params)));
    GenericEngine generic(model);
    JitOptions o = test::jit_options();
    o.flags = "-O0 -std=c++20 -fPIC -shared";
    o.only_set = true;
    o.only = {"energy", "momentum", "reactions", "outputs"};
    auto gen = jit_load(model, codegen::jit_code_generator({}), o);
    const CrosscheckResult r = crosscheck(*gen, generic, 6, 5);
    test::check_within_tolerances(r);
    // the gravity-gradient and modal parts of F on their own scale: at rest on orbit
    std::mt19937 rng(7);
    std::normal_distribution<double> N01;
    for (int k = 0; k < 5; ++k) {
      VecX q = model.q0, u = VecX::Zero(model.nu), Fg, Fr;
      q.head<3>() = 7.0e6 * Vec3(N01(rng), N01(rng), N01(rng)).normalized();
      q.segment<4>(3) = Eigen::Vector4d(N01(rng), N01(rng), N01(rng), N01(rng)).normalized();
      for (int i = 7; i < model.nq; ++i) q(i) = 0.05 * N01(rng);
      gen->forcing(0.0, q, u, VecX::Zero(model.nu), Fg);
      generic.forcing(0.0, q, u, VecX::Zero(model.nu), Fr);
      const VecX rest_r = Fr.tail(model.nu - 3), rest_g = Fg.tail(model.nu - 3);
      INFO("state " << k << ": torques and modal forces " << rest_r.transpose());
      CHECK((rest_g - rest_r).norm() <= 1e-9 * rest_r.norm());
      const EnergyValues eg = gen->energy(0.0, q, u), er = generic.energy(0.0, q, u);
      CHECK(std::abs(eg.V - er.V) <= 1e-13 * std::abs(er.V));
    }
    if (params) {  // a changed mu reaches the generated code without a compile
      VecX values(2);
      values << 3.0e14, 2.0e-3;
      Model changed = model;
      apply_parameters(changed, changed.parameters, values);
      GenericEngine generic2(changed);
      gen->set_parameters(values);
      VecX q = model.q0, u = VecX::Zero(model.nu), Fg, Fr;
      q.head<3>() << 5.0e6, 4.0e6, 2.0e6;
      gen->forcing(0.0, q, u, VecX::Zero(model.nu), Fg);
      generic2.forcing(0.0, q, u, VecX::Zero(model.nu), Fr);
      CHECK((Fg - Fr).norm() <= 1e-12 * Fr.norm());
      CHECK((Fg.tail(model.nu - 3) - Fr.tail(model.nu - 3)).norm() <= 1e-9 * Fr.tail(model.nu - 3).norm());
    }
  }
}

TEST_CASE("central gravity in the generated code: the gravity-gradient torque on a rigid body against 3 mu/r^3 (r^ x I r^)",
          "[central][generator]") {
  const Model model = load_model(test::write_temp("cg_rigid.yaml", R"(name: gg_rigid
gravity: {central: {mu: 3.986004418e14}}
bodies:
  - {name: sat, parent: ground, joint: {type: free}, mass: 500.0, inertia: [300.0, 420.0, 250.0, 12.0, -7.0, 5.0]}
)"));
  JitOptions o = test::jit_options();
  o.flags = "-O0 -std=c++20 -fPIC -shared";
  o.only_set = true;
  o.only = {};
  auto gen = jit_load(model, codegen::jit_code_generator({}), o);
  const Mat3 I_B = (Mat3() << 300, 12, -7, 12, 420, 5, -7, 5, 250).finished();
  std::mt19937 rng(11);
  std::normal_distribution<double> N01;
  for (int k = 0; k < 20; ++k) {
    const Vec3 r = 6.9e6 * Vec3(N01(rng), N01(rng), N01(rng)).normalized();
    const Eigen::Quaterniond Q = Eigen::Quaterniond(N01(rng), N01(rng), N01(rng), N01(rng)).normalized();
    VecX q(7), u = VecX::Zero(6), F;
    q << r, Q.w(), Q.x(), Q.y(), Q.z();
    gen->forcing(0.0, q, u, VecX::Zero(6), F);
    const Mat3 R = Q.toRotationMatrix();
    const Vec3 rh = r.normalized();
    const Vec3 torque_B = R.transpose() * (3 * 3.986004418e14 / std::pow(r.norm(), 3) * rh.cross(R * I_B * R.transpose() * rh));
    INFO("state " << k);
    CHECK((F.segment<3>(3) - torque_B).norm() <= 1e-12 * torque_B.norm());
  }
}
