// Closed-form checks of the generic engine: a rigid pendulum (M, F and the
// pivot reaction), the joint-axis projection of reactions, and the structure
// of M (symmetric positive definite, zero across kinematic chains).
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

constexpr double kPi = 3.14159265358979323846;

const char* kPendulum = R"(
name: pendulum_test
gravity: [0, 0, -9.81]
bodies:
  - name: bob
    parent: ground
    joint: {type: revolute, axis: [0, 1, 0], stiffness: 2.5, damping: 0.3, rest: 0.2}
    mass: 1.7
    com: [0.8, 0, 0]
    inertia: [0.001, 0.004, 0.004, 0, 0, 0]
outputs: [energy, reactions]
)";

}  // namespace

TEST_CASE("pendulum: M, F and pivot reaction in closed form", "[closed-form][generic]") {
  const Model model = load_model(test::write_temp("pendulum_test.yaml", kPendulum));
  GenericEngine engine(model);
  const double m = 1.7, L = 0.8, Iyy = 0.004, g = 9.81, k = 2.5, c = 0.3, rest = 0.2;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-3, 3);
  for (int trial = 0; trial < 20; ++trial) {
    const double th = U(rng), thd = U(rng), tau = U(rng);
    VecX q(1), u(1), t(1), F, udot;
    q << th;
    u << thd;
    t << tau;
    MatX M;
    engine.mass_matrix(q, M);
    engine.forcing(q, u, t, F);
    engine.udot(q, u, t, udot);
    // Rot(y, th) takes x_B to [cos th, 0, -sin th]: the bob hangs down at th = pi/2.
    const double M_exact = m * L * L + Iyy;
    const double F_exact = m * g * L * std::cos(th) - k * (th - rest) - c * thd + tau;
    CHECK(M(0, 0) == Approx(M_exact).epsilon(1e-14));
    CHECK(F(0) == Approx(F_exact).margin(1e-13 * (std::abs(F_exact) + m * g * L)));
    CHECK(udot(0) == Approx(F_exact / M_exact).margin(1e-12));
    std::vector<Reaction> R;
    engine.reactions(q, u, udot, R);
    // Rod tension: with phi = th - pi/2 the angle from the downward vertical,
    // the pivot pulls the bob along -x_B with m (g cos phi + L th_dot^2).
    const double phi = th - kPi / 2;
    CHECK(R[0].force_B(0) == Approx(-m * (g * std::cos(phi) + L * thd * thd)).margin(1e-12));
    // Tangential force: m L th_ddot along -z_B balances gravity's tangential part.
    CHECK(R[0].force_B(2) == Approx(-m * L * udot(0) + m * g * std::cos(th)).margin(1e-12));
    CHECK(R[0].force_B(1) == Approx(0).margin(1e-13));
    // Along the joint axis the reaction torque is what the joint transmits.
    CHECK(R[0].torque_B(1) == Approx(-k * (th - rest) - c * thd + tau).margin(1e-12));
    const EnergyValues E = engine.energy(q, u);
    CHECK(E.T == Approx(0.5 * M_exact * thd * thd).epsilon(1e-14));
    CHECK(E.V == Approx(-m * g * L * std::sin(th) + 0.5 * k * (th - rest) * (th - rest)).margin(1e-13));
  }
}

TEST_CASE("reaction torque along every revolute axis equals spring + damper + input", "[reactions][generic]") {
  for (const char* name : {"v_double3d", "v_branched", "v_free_appendages", "v_prismatic_chain"}) {
    const std::string dir = test::source_path(std::string("tests/reference/") + name);
    const Model model = load_model(dir + "/" + name + ".yaml");
    GenericEngine engine(model);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> U(-1.5, 1.5);
    for (int trial = 0; trial < 5; ++trial) {
      State s = initial_state(model);
      for (int i = 0; i < model.nq; ++i) s.q(i) += U(rng);
      for (const Body& b : model.bodies)
        if (b.joint.type == JointType::free) s.q.segment<4>(b.q_joint + 3).normalize();
      for (int i = 0; i < model.nu; ++i) s.u(i) = U(rng), s.tau(i) = U(rng);
      VecX udot;
      engine.udot(s.q, s.u, s.tau, udot);
      std::vector<Reaction> R;
      engine.reactions(s.q, s.u, udot, R);
      for (std::size_t i = 0; i < model.bodies.size(); ++i) {
        const Body& b = model.bodies[i];
        const Joint& j = b.joint;
        INFO(name << " body " << b.name);
        const double q = s.q(b.q_joint), u = s.u(b.u_joint), tau = s.tau(b.u_joint);
        const double transmitted = -j.stiffness[0] * (q - j.rest[0]) - j.damping[0] * u + tau;
        // The joint axis in B equals the axis in J for revolute and prismatic joints.
        if (j.type == JointType::revolute) CHECK(R[i].torque_B.dot(j.axis_J) == Approx(transmitted).margin(1e-11));
        if (j.type == JointType::prismatic) CHECK(R[i].force_B.dot(j.axis_J) == Approx(transmitted).margin(1e-11));
        if (j.type == JointType::free) {  // a free joint transmits only its inputs
          CHECK(test::rel_err(R[i].force_B, s.tau.segment<3>(b.u_joint), 1.0) < 1e-11);
          CHECK(test::rel_err(R[i].torque_B, s.tau.segment<3>(b.u_joint + 3), 1.0) < 1e-11);
        }
      }
    }
  }
}

TEST_CASE("mass matrix is symmetric positive definite and zero across chains", "[mass-matrix][generic]") {
  for (const char* name : {"v_double3d", "v_branched", "v_free_appendages", "v_prismatic_chain", "v_free_child",
                           "v_flex", "v_flex_free"}) {
    const std::string dir = test::source_path(std::string("tests/reference/") + name);
    const Model model = load_model(dir + "/" + name + ".yaml");
    GenericEngine engine(model);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> U(-1, 1);
    INFO(name);
    for (int trial = 0; trial < 5; ++trial) {
      VecX q = model.q0;
      for (int i = 0; i < model.nq; ++i) q(i) += 0.3 * U(rng);
      MatX M;
      engine.mass_matrix(q, M);
      CHECK((M - M.transpose()).cwiseAbs().maxCoeff() == 0.0);
      Eigen::SelfAdjointEigenSolver<MatX> eig(M);
      CHECK(eig.eigenvalues().minCoeff() > 0);
      // Speeds of two bodies neither of which is an ancestor of the other do not couple.
      for (const Body& a : model.bodies)
        for (const Body& b : model.bodies) {
          const bool related = std::find(a.chain_u.begin(), a.chain_u.end(), b.u_joint) != a.chain_u.end() ||
                               std::find(b.chain_u.begin(), b.chain_u.end(), a.u_joint) != b.chain_u.end();
          const int na = joint_nu(a.joint), nb = joint_nu(b.joint);
          if (!related && na && nb) CHECK(M.block(a.u_joint, b.u_joint, na, nb).cwiseAbs().maxCoeff() == 0.0);
        }
    }
  }
}
