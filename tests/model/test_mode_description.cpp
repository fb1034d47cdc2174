// kanegen check's mode descriptions and whole-spacecraft mass properties
// against closed forms: a uniform cantilever's first bending modes carry
// 61.31 % and 18.83 % of its mass (Euler-Bernoulli, clamped-free), a complete
// set of modes carries all of the nodes that move, and the spacecraft's
// inertia about its centre of mass gives its kinetic energy in a rigid
// rotation about that centre, as the engine computes it.
#include <catch2/catch.hpp>

#include "dynamics/body_terms.hpp"
#include "dynamics/invariants.hpp"
#include "dynamics/kinematics.hpp"
#include "model/mode_description.hpp"
#include "engine/load_model.hpp"
#include "sim/mass_properties.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

Model beam_model(const std::string& beam) {
  return load_model(test::write_temp("beam.yaml", R"(
name: beam
bodies:
  - name: hub
    parent: ground
    joint: {type: free}
    mass: 10.0
    inertia: [1, 1, 1, 0, 0, 0]
  - name: arm
    parent: hub
    joint: {type: fixed}
    flexible:
      beam: )" + beam + "\n"));
}

}  // namespace

TEST_CASE("mode description: a cantilever's bending modes, their directions and effective masses", "[modes]") {
  // along y, EI about z 4000 and about x 250: the weak plane bends along z first
  const Model m = beam_model("{length: 5.0, direction: y, mass_per_length: 4.0, EI: [4000.0, 250.0], elements: 60, modes: 3}");
  const Body& arm = m.bodies[m.body_index("arm")];
  const FlexibleBodyModes d = describe_modes(arm);
  CHECK(d.long_axis == 1);
  REQUIRE(d.modes.size() == 3);
  CHECK(d.modes[0].shape == "bending: deflection along z (about x)");
  CHECK(d.modes[1].shape == "bending: deflection along x (about z)");  // (4.694/1.875)^2 = 6.3 > sqrt(16)
  CHECK(d.modes[2].shape == "bending: deflection along z (about x)");
  const double mass = 20.0;
  INFO("effective mass fractions " << d.modes[0].effective_mass.z() / mass << ", "
                                   << d.modes[1].effective_mass.x() / mass << ", "
                                   << d.modes[2].effective_mass.z() / mass);
  CHECK(std::abs(d.modes[0].effective_mass.z() / mass - 0.6131) < 0.01);
  CHECK(std::abs(d.modes[1].effective_mass.x() / mass - 0.6131) < 0.01);
  CHECK(std::abs(d.modes[2].effective_mass.z() / mass - 0.1883) < 0.01);
  CHECK(d.modes[0].effective_mass.x() < 1e-12 * mass);
  CHECK(d.modes[0].effective_mass.y() < 1e-12 * mass);
  // a bending mode along z turns about x: its effective inertia about O's x axis, none about z
  CHECK(d.modes[0].effective_inertia.x() > 0.0);
  CHECK(d.modes[0].effective_inertia.z() < 1e-12 * d.node_inertia_O.z());
  CHECK(std::abs(d.node_mass - (mass - arm.flex->nodes[0].mass)) < 1e-12 * mass);  // the clamped root node left out
}

TEST_CASE("mode description: a complete set of modes carries every moving node's mass, torsion and axial named", "[modes]") {
  // 8 elements, lumped masses, slopes condensed: 8 modes per bending plane, 8 axial, 8 torsion
  const Model m = beam_model(
      "{length: 2.0, direction: x, mass_per_length: 3.0, EI: [900.0, 400.0], GJ: 50.0, EA: 1.0e5, "
      "polar_inertia_per_length: 0.003, elements: 8, modes: 32}");
  const Body& arm = m.bodies[m.body_index("arm")];
  const FlexibleBodyModes d = describe_modes(arm);
  CHECK(d.long_axis == 0);
  Vec3 sum = Vec3::Zero();
  int torsion = 0, axial = 0;
  for (const ModeDescription& md : d.modes) {
    sum += md.effective_mass;
    torsion += md.shape == "torsion about x";
    axial += md.shape == "axial along x";
  }
  const double moving = 3.0 * 2.0 - arm.flex->nodes[0].mass;  // node 1 is clamped at O
  CHECK(std::abs(d.node_mass - moving) <= 1e-12 * moving);      // and left out of the moving mass
  INFO("sum of effective masses " << sum.transpose() << ", moving nodes " << moving);
  CHECK(std::abs(sum.x() - moving) <= 1e-9 * moving);
  CHECK(std::abs(sum.y() - moving) <= 1e-9 * moving);
  CHECK(std::abs(sum.z() - moving) <= 1e-9 * moving);
  CHECK(torsion == 8);
  CHECK(axial == 8);
}

TEST_CASE("mass properties: the whole spacecraft's mass, centre of mass and inertia", "[modes]") {
  const Model model = load_model(test::source_path("models/gnc/slew_spacecraft.yaml"));
  State s = initial_state(model);
  s.q(model.q_index("bus.x")) = 1.0;  // away from the origin, turned
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  s.q(model.q_index("bus.qw")) = turn.w();
  s.q(model.q_index("bus.qx")) = turn.x();
  s.q(model.q_index("bus.qy")) = turn.y();
  s.q(model.q_index("bus.qz")) = turn.z();
  const SystemMassProperties p = system_mass_properties(model, s);
  CHECK(std::abs(p.mass - 652.0) < 1e-12 * 652.0);  // bus 600, wheels 3 x 4, arrays 2 x 20
  // the arrays are symmetric about the bus origin: the com is the bus's and the wheels'
  const Vec3 com_B = (600.0 * Vec3(0.01, 0.0, 0.02) + 4.0 * Vec3(0.3, 0.3, 0.3)) / 652.0;
  CHECK((p.com_N - (Vec3(1, 0, 0) + turn.toRotationMatrix() * com_B)).norm() < 1e-12);
  // rigid rotation w about the com (bus speeds such that v_com = 0, wheels and arrays carried along):
  // T = 1/2 w^T J_com w, as the engine's kinetic energy
  Workspace<double> ws(model);
  for (const Vec3& w_N : {Vec3(0.1, 0, 0), Vec3(0, 0.2, 0), Vec3(0.03, -0.05, 0.07)}) {
    const Mat3 R = turn.toRotationMatrix();
    const Vec3 w_B = R.transpose() * w_N;
    const Vec3 v_O_B = -w_B.cross(com_B);  // v_O = v_com + w x (O - com)
    State r = s;
    r.u(model.speed_index("bus.vx")) = v_O_B.x();
    r.u(model.speed_index("bus.vy")) = v_O_B.y();
    r.u(model.speed_index("bus.vz")) = v_O_B.z();
    r.u(model.speed_index("bus.wx")) = w_B.x();
    r.u(model.speed_index("bus.wy")) = w_B.y();
    r.u(model.speed_index("bus.wz")) = w_B.z();
    compute_kinematics(model, ws, r.t, r.q, r.u);
    compute_body_terms(model, ws);
    const double T = compute_energy(model, ws, r.q).T;
    INFO("w_N " << w_N.transpose());
    CHECK(std::abs(T - 0.5 * w_N.dot(p.J_com_N * w_N)) <= 1e-12 * T);
  }
  CHECK(p.principal_moments(0) <= p.principal_moments(1));
  CHECK((p.J_com_N * p.principal_axes_N.col(2) - p.principal_moments(2) * p.principal_axes_N.col(2)).norm() < 1e-9);
}

TEST_CASE("mass properties: the inertia about the centre of mass is the same at 7,000 km from N's origin as at "
          "the origin, to round-off (no cancellation)",
          "[modes][central]") {
  for (const char* file : {"models/gnc/slew_spacecraft.yaml", "models/flexible_spacecraft.yaml"}) {
    INFO(file);
    const Model model = load_model(test::source_path(file));
    State s = initial_state(model);
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
    s.q.segment<4>(model.q_index("bus.qw")) << turn.w(), turn.x(), turn.y(), turn.z();
    for (std::size_t k = 0; k < model.q_names.size(); ++k)  // the arrays deflected
      if (model.q_names[k].find(".eta") != std::string::npos) s.q(static_cast<int>(k)) = 0.02;
    s.q.segment<3>(model.q_index("bus.x")).setZero();
    const SystemMassProperties at_origin = system_mass_properties(model, s);
    s.q.segment<3>(model.q_index("bus.x")) = Vec3(4.1e6, -3.3e6, 4.6e6);  // |r| = 7.0e6 m
    const SystemMassProperties far = system_mass_properties(model, s);
    const double J = at_origin.J_com_N.norm();
    CHECK((far.J_com_N - at_origin.J_com_N).norm() <= 1e-12 * J);
    CHECK((far.principal_moments - at_origin.principal_moments).norm() <= 1e-12 * J);
    CHECK(((far.com_N - Vec3(4.1e6, -3.3e6, 4.6e6)) - at_origin.com_N).norm() <= 1e-9);
    CHECK(far.mass == at_origin.mass);
  }
}
