// The generator's body frames (codegen/joint_frames.hpp) are a convention:
// the framed model, evaluated by the generic engine at q + angle_offset,
// has the model's M, F and reactions (these turned and moved back by R_BB'
// and o_B). And the frames are the ones promised: the offset from a body to
// its main child, in the child's joint axes, is (a, 0, d) (origins at the
// feet of the common normals), the turn between them about x alone; to a
// tree's other revolute children, a turn about z, then about x. A tree's
// generated code in both u-dot forms against the generic engine.
#include <catch2/catch.hpp>

#include <random>
#include <regex>

#include "codegen/generator.hpp"
#include "codegen/joint_frames.hpp"
#include "engine/generic_engine.hpp"
#include "engine/generated_engine.hpp"
#include "engine/load_model.hpp"
#include "tests/support/crosscheck_checks.hpp"
#include "tests/support/random_chain.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

/// The model without joint springs and dampers: the framed model's joint angles are shifted by the
/// offsets, its springs' rest angles are not (the generator applies the offsets inside the joint rotation).
Model without_springs(Model m) {
  for (Body& b : m.bodies) b.joint.stiffness.fill(0.0), b.joint.damping.fill(0.0);
  return m;
}

}  // namespace

TEST_CASE("joint frames: the offset to a main child is (a, 0, d) in its joint axes, the turn about x",
          "[generator][joint-frames]") {
  const Model model = load_model(test::write_temp("frames_chain8.yaml", test::random_chain(8, 5)));
  const codegen::FramedModel fr = codegen::choose_joint_frames(model);
  int shifted = 0;
  for (std::size_t c = 1; c < fr.model.bodies.size(); ++c) {
    const Joint& jc = fr.model.bodies[c].joint;
    const Vec3 p_J = jc.R_PJ.transpose() * jc.p_PJ;
    INFO("body " << fr.model.bodies[c].name << ": p_J = " << p_J.transpose());
    CHECK(std::abs(p_J.y()) <= 1e-13 * p_J.norm());
    CHECK(jc.R_PJ(0, 0) == 1.0);  // Rx(alpha)
    CHECK(jc.R_PJ(0, 1) == 0.0);
    CHECK(jc.R_PJ(0, 2) == 0.0);
    // the origin slid along the joint axis of the model
    const int p = fr.model.bodies[c].parent;
    const Vec3 axis = model.bodies[p].joint.axis_J.normalized();
    CHECK((fr.o_B[p] - axis * axis.dot(fr.o_B[p])).norm() <= 1e-15 * (1 + fr.o_B[p].norm()));
    shifted += fr.o_B[p].norm() > 0 ? 1 : 0;
  }
  CHECK(shifted == 7);  // every body with a child: random axes are skew
}

TEST_CASE("joint frames: a tree's other revolute children turn by Rz(beta) Rx(alpha) from the parent",
          "[generator][joint-frames]") {
  const Model model = load_model(test::write_temp("frames_tree15.yaml", test::random_tree(15, 4)));
  const codegen::FramedModel fr = codegen::choose_joint_frames(model);
  int screws = 0;
  for (std::size_t c = 1; c < fr.model.bodies.size(); ++c) {
    const Body& b = fr.model.bodies[c];
    INFO("body " << b.name << ", screw angle " << fr.screw_angle[c]);
    // the first (main) child of a parent with two like subtrees is the one listed first: link 2k
    const bool main_child = c % 2 == 1;  // index c is link c + 1
    const bool screwed = !main_child && b.joint.type == JointType::revolute;
    CHECK((fr.screw_angle[c] != 0.0) == screwed);
    screws += fr.screw_angle[c] != 0.0 ? 1 : 0;
    const Mat3 R_SJ = codegen::rot_z(fr.screw_angle[c]).transpose() * b.joint.R_PJ;
    if (b.joint.type == JointType::revolute) {  // Rx(alpha); Rz(delta) joined to the joint angle
      CHECK(std::abs(R_SJ(0, 0) - 1.0) <= 1e-15);
      CHECK(std::abs(R_SJ(0, 1)) + std::abs(R_SJ(0, 2)) + std::abs(R_SJ(1, 0)) + std::abs(R_SJ(2, 0)) <= 1e-15);
      CHECK(std::abs(R_SJ(1, 1) - R_SJ(2, 2)) <= 1e-15);
    }
    // a leaf's origin at the foot of the perpendicular from its parent's: no offset along its axis
    // ((a, 0, 0) from a main child's parent, whose origin is at the foot of their common normal)
    const Vec3 p_J = b.joint.R_PJ.transpose() * b.joint.p_PJ;
    INFO("p_J = " << p_J.transpose());
    if (c >= 7) {  // links 8 to 15
      CHECK(std::abs(p_J.z()) <= 1e-14 * p_J.norm());
      if (main_child) CHECK(std::abs(p_J.y()) <= 1e-14 * p_J.norm());
    }
  }
  CHECK(screws == 6);  // links 3, 7, 9, 11, 13, 15 (link 5, the other child of link 2, is prismatic)
}

TEST_CASE("joint frames: a tree with screw turns, generated in both u-dot forms, against the generic engine",
          "[generator][joint-frames][jit]") {
  // reactions and point sensors on a screwed child (link 3) and on the prismatic one (link 5)
  const std::string yaml = test::random_tree(9, 8) +
                           "outputs:\n  - reactions\n"
                           "  - {name: link3_point_a, type: acceleration, body: link3, point: [0.1, -0.05, 0.2]}\n"
                           "  - {name: link5_point_v, type: velocity, body: link5, point: [-0.1, 0.05, 0.1]}\n";
  const Model model = load_model(test::write_temp("frames_tree9.yaml", yaml));
  REQUIRE(codegen::choose_joint_frames(model).screw_angle[2] != 0.0);
  GenericEngine generic(model);
  for (auto& e : test::generated_engines_in_both_forms(model)) {
    INFO("form " << e->udot_form());
    const CrosscheckResult r = crosscheck(*e, generic, 6, 17);
    test::check_within_tolerances(r);
    CHECK(r.worst.count("reactions") == 1);
    CHECK(r.worst.count("outputs") == 1);
  }
}

TEST_CASE("joint frames: a screw-turned child's position and a moved leaf's mass and inertia as runtime parameters",
          "[generator][joint-frames][parameters][jit]") {
  // link3 is turned (not link1's main child) and its joint's position is a runtime parameter (given in the
  // parent's model axes: the generator turns it into the screw's axes); link9 is a turned leaf whose origin
  // slid along its axis, with its mass and inertia (about the centre of mass) at run time
  const std::string yaml = test::random_tree(9, 8) + "parameters: [link3.position, link9.mass, link9.inertia]\n";
  const Model model = load_model(test::write_temp("frames_tree9_params.yaml", yaml));
  const codegen::FramedModel fr = codegen::choose_joint_frames(model);
  REQUIRE(fr.screw_angle[2] != 0.0);
  REQUIRE(fr.screw_angle[8] != 0.0);
  REQUIRE(fr.o_B[8].norm() > 0.0);
  auto generated = test::generated_engine(model);
  VecX p = Engine::nominal_parameters(model);
  p(0) += 0.05, p(1) -= 0.03, p(2) += 0.02;  // link3.position
  p(3) *= 1.5;                                // link9.mass
  p(4) *= 1.2, p(5) *= 1.1, p(6) *= 1.15, p(7) = 1e-4, p(8) = -2e-4, p(9) = 1e-4;
  test::check_within_tolerances(test::crosscheck_at_parameters(*generated, model, p, 5, 23));
}

TEST_CASE("joint frames: axis-aligned turns leave no round-off constants", "[generator][joint-frames][jit]") {
  // link2 is link1's other child (link3's subtree is larger), its axis along link1's x axis, which is the
  // common normal to link3's: turned by a quarter turn about z (cos = 6e-17 unless snapped); link5 is
  // prismatic, its dense joint frame turned by z-x-z factors
  const std::string yaml = R"(name: aligned_tree
gravity: [0, 0, -9.81]
bodies:
  - {name: link1, parent: ground, joint: {type: revolute, axis: [0, 0, 1]}, mass: 2, com: [0.1, 0.02, 0.05], inertia: [0.02, 0.03, 0.04, 0.001, 0, 0]}
  - {name: link2, parent: link1, joint: {type: revolute, axis: [1, 0, 0], position: [0.3, 0, 0.1]}, mass: 1, com: [0.1, 0, 0.02], inertia: [0.01, 0.02, 0.02, 0, 0, 0]}
  - {name: link3, parent: link1, joint: {type: revolute, axis: [0, 1, 0], position: [0, 0.3, -0.1]}, mass: 1, com: [0, 0.1, 0.03], inertia: [0.02, 0.01, 0.02, 0, 0, 0]}
  - {name: link4, parent: link2, joint: {type: revolute, axis: [0, 0, 1], position: [0.2, 0, 0]}, mass: 0.5, com: [0.05, 0.01, 0], inertia: [0.005, 0.005, 0.005, 0, 0, 0]}
  - {name: link5, parent: link3, joint: {type: prismatic, axis: [0.6, 0, 0.8], position: [0, 0.2, 0], rotation: {rpy: [0.3, -0.4, 0.5]}}, mass: 0.5, com: [0.02, 0.01, 0.05], inertia: [0.004, 0.005, 0.006, 0, 0, 0]}
  - {name: link6, parent: link5, joint: {type: revolute, axis: [0, 1, 0], position: [0.1, 0, 0.1]}, mass: 0.3, com: [0.05, 0, 0], inertia: [0.002, 0.003, 0.003, 0, 0, 0]}
)";
  const Model model = load_model(test::write_temp("frames_aligned_tree.yaml", yaml));
  const codegen::FramedModel fr = codegen::choose_joint_frames(model);
  REQUIRE(std::abs(std::abs(fr.screw_angle[1]) - M_PI / 2) < 1e-12);
  const codegen::EmittedModel m = codegen::generate(model);
  const std::regex constant(R"(inline constexpr double (\w+) = ([-+0-9.eE]+);)");
  int constants = 0;
  for (auto it = std::sregex_iterator(m.constants.begin(), m.constants.end(), constant); it != std::sregex_iterator();
       ++it, ++constants) {
    const double v = std::stod((*it)[2].str());
    INFO((*it)[1].str() << " = " << v);
    CHECK(std::abs(v) >= 1e-13);  // (exact zeros are folded, never named)
  }
  CHECK(constants > 50);
  GenericEngine generic(model);
  for (auto& e : test::generated_engines_in_both_forms(model)) {
    INFO("form " << e->udot_form());
    test::check_within_tolerances(crosscheck(*e, generic, 4, 31));
  }
}

TEST_CASE("joint frames: the framed model at q + offset has the model's M, F and reactions",
          "[generator][joint-frames]") {
  const std::string chain = test::write_temp("frames_chain6.yaml", test::random_chain(6, 9));
  const std::string tree = test::write_temp("frames_tree11.yaml", test::random_tree(11, 6));
  for (const std::string& file : {chain, tree, test::source_path("models/extreme/wide_tree.yaml"),
                                  test::source_path("models/chain5_prismatic.yaml")}) {
    INFO(file);
    const Model model = without_springs(load_model(file));
    const codegen::FramedModel fr = codegen::choose_joint_frames(model);
    GenericEngine g(model), gf(fr.model);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> d(-1.0, 1.0);
    for (int k = 0; k < 3; ++k) {
      VecX q = model.q0, u(model.nu), tau(model.nu);
      for (const Body& b : model.bodies)
        if (b.joint.type == JointType::revolute || b.joint.type == JointType::prismatic) q(b.q_joint) = d(rng);
      for (int i = 0; i < model.nu; ++i) u(i) = d(rng), tau(i) = d(rng);
      VecX qf = q;
      for (std::size_t j = 0; j < model.bodies.size(); ++j)
        if (fr.angle_offset[j] != 0.0) qf(model.bodies[j].q_joint) += fr.angle_offset[j];
      MatX M, Mf;
      VecX F, Ff, ud, udf;
      g.mass_matrix(q, M);
      gf.mass_matrix(qf, Mf);
      g.forcing(q, u, tau, F);
      gf.forcing(qf, u, tau, Ff);
      CHECK(test::rel_err(Mf, M) < 1e-13);
      CHECK(test::rel_err(Ff, F) < 1e-13);
      g.udot(q, u, tau, ud);
      std::vector<Reaction> R, Rf;
      g.reactions(q, u, ud, R);
      gf.reactions(qf, u, ud, Rf);
      REQUIRE(R.size() == Rf.size());
      double scale = 0, err = 0;
      for (std::size_t j = 0; j < R.size(); ++j) {
        const Mat3& Q = fr.R_BBp[j];
        const Vec3 f = Q * Rf[j].force_B, t = Q * Rf[j].torque_B + fr.o_B[j].cross(f);
        scale = std::max({scale, R[j].force_B.norm(), R[j].torque_B.norm()});
        err = std::max({err, (f - R[j].force_B).norm(), (t - R[j].torque_B).norm()});
      }
      CHECK(err <= 1e-12 * scale);
    }
  }
}

TEST_CASE("joint frames: sensors and reactions of bodies whose origin moved, generated against generic",
          "[generator][joint-frames][jit]") {
  // a random chain with a reaction sensor and point sensors on a link in the middle (its origin moves)
  const std::string yaml = test::random_chain(5, 13) +
                           "outputs:\n  - reactions\n"
                           "  - {name: link3_reaction, type: reaction, joint: link3}\n"
                           "  - {name: link3_point_v, type: velocity, body: link3, point: [0.1, -0.05, 0.2]}\n"
                           "  - {name: link3_point_a, type: acceleration, body: link3, point: [0.1, -0.05, 0.2]}\n";
  const Model model = load_model(test::write_temp("frames_sensors.yaml", yaml));
  REQUIRE(codegen::choose_joint_frames(model).o_B[2].norm() > 0);  // link3 moves
  auto e = test::generated_engine(model);
  GenericEngine g(model);
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  for (int k = 0; k < 3; ++k) {
    VecX q(model.nq), u(model.nu), tau(model.nu);
    for (int i = 0; i < model.nq; ++i) q(i) = d(rng);
    for (int i = 0; i < model.nu; ++i) u(i) = d(rng), tau(i) = d(rng);
    VecX y, yg, ud;
    e->outputs(0.0, q, u, tau, y);
    g.outputs(0.0, q, u, tau, yg);
    CHECK(test::rel_err(y, yg) < 1e-12);
    g.udot(q, u, tau, ud);
    std::vector<Reaction> R, Rg;
    e->reactions(q, u, ud, R);
    g.reactions(q, u, ud, Rg);
    for (std::size_t j = 0; j < R.size(); ++j) {
      CHECK((R[j].force_B - Rg[j].force_B).norm() <= 1e-12 * (1 + Rg[j].force_B.norm()));
      CHECK((R[j].torque_B - Rg[j].torque_B).norm() <= 1e-12 * (1 + Rg[j].torque_B.norm()));
    }
  }
}
