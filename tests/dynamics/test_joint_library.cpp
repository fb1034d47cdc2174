// The joint library (model/joints/) against independent constructions:
//   - universal, gimbal, cylindrical and planar joints against the same
//     mechanism built from revolute and prismatic joints with massless
//     intermediate bodies (same coordinates, same speeds): M, F, u-dot,
//     energy, momentum and reactions to round-off, on a free base, with
//     arbitrary axes and joint frames and springs per coordinate;
//   - a ball joint against a gimbal of three revolutes at the same attitude
//     and angular velocity (the free base's accelerations, reactions, energy
//     and momentum agree: the ball's speeds are the gimbal's omega), its
//     damper as -c omega;
//   - the heavy (Lagrange) top on a ball joint and on a gimbal: same attitude
//     history, E and H_z conserved, steady precession at the closed-form rate;
//   - generated against generic for every new joint.
#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <cmath>
#include <random>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/rotation.hpp"
#include "sim/crosscheck.hpp"
#include "sim/integrators.hpp"
#include "sim/simulate.hpp"
#include "model/state_io.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

// A free bus with four branches, each a multi-dof joint on an arbitrary joint
// frame with springs per coordinate; the gimbal carries a revolute child.
const char* kMultiDof = R"(name: multidof
gravity: [0.3, -0.2, -9.81]
bodies:
  - name: bus
    parent: ground
    joint: {type: free}
    mass: 50.0
    com: [0.1, -0.05, 0.02]
    inertia: [10.0, 12.0, 14.0, 0.3, -0.2, 0.1]
  - name: uj
    parent: bus
    joint: {type: universal, axes: [[0.6, 0.8, 0], [0, 0.6, 0.8]], position: [1.0, 0.2, -0.1],
            rotation: {rpy: [0.3, -0.2, 0.5]}, stiffness: [2.0, 3.0], damping: [0.1, 0.2], rest: [0.1, -0.2]}
    mass: 2.0
    com: [0.3, 0.1, 0.05]
    inertia: [0.2, 0.3, 0.25, 0.01, 0.02, -0.01]
  - name: gim
    parent: bus
    joint: {type: gimbal, sequence: zyx, position: [-0.8, 0.4, 0.3], rotation: {rpy: [-0.4, 0.7, 0.1]},
            stiffness: [1.0, 2.0, 3.0], damping: [0.1, 0.2, 0.3], rest: [0.1, 0.2, 0.3]}
    mass: 3.0
    com: [0.2, -0.1, 0.4]
    inertia: [0.4, 0.5, 0.3, 0.02, -0.01, 0.03]
  - name: gim_arm
    parent: gim
    joint: {type: revolute, axis: [0, 0, 1], position: [0.5, 0, 0.2], stiffness: 0.5}
    mass: 0.7
    com: [0.2, 0, 0]
    inertia: [0.01, 0.03, 0.03, 0, 0, 0]
  - name: cyl
    parent: bus
    joint: {type: cylindrical, axis: [0, 0.6, 0.8], position: [0.2, -0.9, 0.4], rotation: {rpy: [0.2, 0.1, -0.3]},
            stiffness: [1.0, 5.0], damping: 0.2, rest: [0.05, 0.1]}
    mass: 1.5
    com: [0.1, 0.2, -0.1]
    inertia: [0.1, 0.2, 0.15, 0.01, 0, 0.02]
  - name: pla
    parent: bus
    joint: {type: planar, position: [0.3, 0.5, -0.7], rotation: {rpy: [0.5, -0.3, 0.2]},
            stiffness: [1.0, 2.0, 3.0], damping: [0.3, 0.2, 0.1], rest: [0.1, -0.1, 0.2]}
    mass: 1.2
    com: [0.2, -0.3, 0.1]
    inertia: [0.05, 0.06, 0.07, 0.001, 0.002, 0.003]
outputs: [energy, momentum, reactions]
)";

// The same mechanism from revolute and prismatic joints and massless bodies
// (zyx: z, then y, then x about the turned frames).
const char* kMultiDofChains = R"(name: multidof_chains
gravity: [0.3, -0.2, -9.81]
bodies:
  - name: bus
    parent: ground
    joint: {type: free}
    mass: 50.0
    com: [0.1, -0.05, 0.02]
    inertia: [10.0, 12.0, 14.0, 0.3, -0.2, 0.1]
  - name: uj_1
    parent: bus
    joint: {type: revolute, axis: [0.6, 0.8, 0], position: [1.0, 0.2, -0.1], rotation: {rpy: [0.3, -0.2, 0.5]},
            stiffness: 2.0, damping: 0.1, rest: 0.1}
    mass: 0
    com: [0, 0, 0]
    inertia: [0, 0, 0, 0, 0, 0]
  - name: uj
    parent: uj_1
    joint: {type: revolute, axis: [0, 0.6, 0.8], stiffness: 3.0, damping: 0.2, rest: -0.2}
    mass: 2.0
    com: [0.3, 0.1, 0.05]
    inertia: [0.2, 0.3, 0.25, 0.01, 0.02, -0.01]
  - name: gim_1
    parent: bus
    joint: {type: revolute, axis: [0, 0, 1], position: [-0.8, 0.4, 0.3], rotation: {rpy: [-0.4, 0.7, 0.1]},
            stiffness: 1.0, damping: 0.1, rest: 0.1}
    mass: 0
    com: [0, 0, 0]
    inertia: [0, 0, 0, 0, 0, 0]
  - name: gim_2
    parent: gim_1
    joint: {type: revolute, axis: [0, 1, 0], stiffness: 2.0, damping: 0.2, rest: 0.2}
    mass: 0
    com: [0, 0, 0]
    inertia: [0, 0, 0, 0, 0, 0]
  - name: gim
    parent: gim_2
    joint: {type: revolute, axis: [1, 0, 0], stiffness: 3.0, damping: 0.3, rest: 0.3}
    mass: 3.0
    com: [0.2, -0.1, 0.4]
    inertia: [0.4, 0.5, 0.3, 0.02, -0.01, 0.03]
  - name: gim_arm
    parent: gim
    joint: {type: revolute, axis: [0, 0, 1], position: [0.5, 0, 0.2], stiffness: 0.5}
    mass: 0.7
    com: [0.2, 0, 0]
    inertia: [0.01, 0.03, 0.03, 0, 0, 0]
  - name: cyl_1
    parent: bus
    joint: {type: revolute, axis: [0, 0.6, 0.8], position: [0.2, -0.9, 0.4], rotation: {rpy: [0.2, 0.1, -0.3]},
            stiffness: 1.0, damping: 0.2, rest: 0.05}
    mass: 0
    com: [0, 0, 0]
    inertia: [0, 0, 0, 0, 0, 0]
  - name: cyl
    parent: cyl_1
    joint: {type: prismatic, axis: [0, 0.6, 0.8], stiffness: 5.0, damping: 0.2, rest: 0.1}
    mass: 1.5
    com: [0.1, 0.2, -0.1]
    inertia: [0.1, 0.2, 0.15, 0.01, 0, 0.02]
  - name: pla_1
    parent: bus
    joint: {type: prismatic, axis: [1, 0, 0], position: [0.3, 0.5, -0.7], rotation: {rpy: [0.5, -0.3, 0.2]},
            stiffness: 1.0, damping: 0.3, rest: 0.1}
    mass: 0
    com: [0, 0, 0]
    inertia: [0, 0, 0, 0, 0, 0]
  - name: pla_2
    parent: pla_1
    joint: {type: prismatic, axis: [0, 1, 0], stiffness: 2.0, damping: 0.2, rest: -0.1}
    mass: 0
    com: [0, 0, 0]
    inertia: [0, 0, 0, 0, 0, 0]
  - name: pla
    parent: pla_2
    joint: {type: revolute, axis: [0, 0, 1], stiffness: 3.0, damping: 0.1, rest: 0.2}
    mass: 1.2
    com: [0.2, -0.3, 0.1]
    inertia: [0.05, 0.06, 0.07, 0.001, 0.002, 0.003]
outputs: [energy, momentum, reactions]
)";

/// A free bus with a body on a ball joint (or the same body on a gimbal of
/// three revolutes about the joint frame's x, y, z when `gimbal`).
std::string ball_model(bool gimbal, double damping) {
  std::string joint = gimbal ? "{type: gimbal, sequence: xyz, position: [0.6, -0.3, 0.4], rotation: {rpy: [0.2, -0.5, 0.3]}}"
                             : fmt::format("{{type: ball, position: [0.6, -0.3, 0.4], rotation: {{rpy: [0.2, -0.5, 0.3]}}, "
                                           "damping: {}}}",
                                           damping);
  return fmt::format(R"(name: ball_or_gimbal
gravity: [0, 0, -9.81]
bodies:
  - name: bus
    parent: ground
    joint: {{type: free}}
    mass: 20.0
    com: [0.05, 0.02, -0.03]
    inertia: [4.0, 5.0, 6.0, 0.1, 0.05, -0.08]
  - name: pend
    parent: bus
    joint: {}
    mass: 2.5
    com: [0.1, -0.2, -0.5]
    inertia: [0.3, 0.25, 0.1, 0.01, -0.02, 0.03]
outputs: [energy, momentum, reactions]
)",
                     joint);
}

struct Eval {
  MatX M;
  VecX F, udot;
  EnergyValues E;
  MomentumValues H;
  std::vector<Reaction> R;
};

Eval evaluate(Engine& e, const VecX& q, const VecX& u, const VecX& tau) {
  Eval r;
  e.mass_matrix(q, r.M);
  e.forcing(q, u, tau, r.F);
  e.udot(q, u, tau, r.udot);
  r.E = e.energy(q, u);
  r.H = e.momentum(q, u);
  e.reactions(q, u, r.udot, r.R);
  return r;
}

double reaction_err(const Reaction& a, const Reaction& b) {
  const double scale = std::max({1.0, b.force_B.norm(), b.torque_B.norm()});
  return std::max((a.force_B - b.force_B).norm(), (a.torque_B - b.torque_B).norm()) / scale;
}

/// q, u, tau at random (quaternions unit).
void random_state(const Model& m, std::mt19937& rng, VecX& q, VecX& u, VecX& tau) {
  std::uniform_real_distribution<double> U(-1, 1);
  std::normal_distribution<double> N(0, 1);
  q = m.q0, u.resize(m.nu), tau.resize(m.nu);
  for (const Body& b : m.bodies)
    random_coordinates(b.joint, [&] { return U(rng); }, [&] { return N(rng); }, q.data() + b.q_joint);
  for (int i = 0; i < m.nu; ++i) u(i) = 2 * U(rng), tau(i) = U(rng);
}

}  // namespace

TEST_CASE("joints: universal, gimbal, cylindrical and planar equal revolute/prismatic chains with massless bodies",
          "[joints]") {
  const Model A = load_model(test::write_temp("multidof.yaml", kMultiDof));
  const Model B = load_model(test::write_temp("multidof_chains.yaml", kMultiDofChains));
  REQUIRE(A.nq == B.nq);
  REQUIRE(A.nu == B.nu);
  CHECK(A.q_names[7] == "uj.angle1");
  CHECK(A.u_names[6] == "uj.angle1_rate");
  CHECK(A.u_names[8] == "gim.angle1_rate");
  GenericEngine ea(A), eb(B);
  std::mt19937 rng(7);
  double worst = 0;
  for (int s = 0; s < 20; ++s) {
    VecX q, u, tau;
    random_state(B, rng, q, u, tau);
    const Eval a = evaluate(ea, q, u, tau), b = evaluate(eb, q, u, tau);
    worst = std::max({worst, test::rel_err(a.M, b.M), test::rel_err(a.F, b.F), test::rel_err(a.udot, b.udot)});
    worst = std::max(worst, std::abs(a.E.T - b.E.T) / std::max(1.0, std::abs(b.E.T)));
    worst = std::max(worst, std::abs(a.E.V - b.E.V) / std::max(1.0, std::abs(b.E.V)));
    worst = std::max(worst, (a.H.p_N - b.H.p_N).norm() / std::max(1.0, b.H.p_N.norm()));
    worst = std::max(worst, (a.H.H_N - b.H.H_N).norm() / std::max(1.0, b.H.H_N.norm()));
    for (const Body& body : A.bodies) worst = std::max(worst, reaction_err(a.R[A.body_index(body.name)], b.R[B.body_index(body.name)]));
  }
  INFO("largest relative difference " << worst);
  CHECK(worst < test::kRoundoff);
}

TEST_CASE("joints: a ball joint equals a gimbal at the same attitude and angular velocity, its damper is -c w",
          "[joints]") {
  const Model ball = load_model(test::write_temp("ball.yaml", ball_model(false, 0.0)));
  const Model damped = load_model(test::write_temp("ball_damped.yaml", ball_model(false, 0.7)));
  const Model gim = load_model(test::write_temp("gimbal.yaml", ball_model(true, 0.0)));
  CHECK(ball.q_names[7] == "pend.qw");
  CHECK(ball.u_names[6] == "pend.wx");
  REQUIRE(ball.quaternions.size() == 2);
  GenericEngine eb(ball), ed(damped), eg(gim);
  std::mt19937 rng(11);
  double worst = 0, worst_damper = 0;
  for (int s = 0; s < 20; ++s) {
    VecX qg, ug, tau;
    random_state(gim, rng, qg, ug, tau);
    tau.setZero();
    // the ball's state: quaternion of Rx Ry Rz, w = Gamma(theta) theta_dot in B
    const double* th = qg.data() + 7;
    const Mat3 Rx = axis_angle_R<double>(Vec3::UnitX(), th[0]), Ry = axis_angle_R<double>(Vec3::UnitY(), th[1]),
               Rz = axis_angle_R<double>(Vec3::UnitZ(), th[2]);
    const Eigen::Quaterniond quat(Rx * Ry * Rz);
    const Vec3 w = Rz.transpose() * Ry.transpose() * Vec3::UnitX() * ug(6) + Rz.transpose() * Vec3::UnitY() * ug(7) +
                   Vec3::UnitZ() * ug(8);
    VecX qb(11), ub(9);
    qb << qg.head(7), quat.w(), quat.x(), quat.y(), quat.z();
    ub << ug.head(6), w;
    const Eval g = evaluate(eg, qg, ug, tau), b = evaluate(eb, qb, ub, VecX::Zero(9));
    worst = std::max(worst, test::rel_err(b.udot.head(6), g.udot.head(6)));  // the base's accelerations
    worst = std::max(worst, std::abs(b.E.T - g.E.T) / std::max(1.0, std::abs(g.E.T)));
    worst = std::max(worst, std::abs(b.E.V - g.E.V) / std::max(1.0, std::abs(g.E.V)));
    worst = std::max(worst, (b.H.H_N - g.H.H_N).norm() / std::max(1.0, g.H.H_N.norm()));
    worst = std::max(worst, (b.H.p_N - g.H.p_N).norm() / std::max(1.0, g.H.p_N.norm()));
    for (int k = 0; k < 2; ++k) worst = std::max(worst, reaction_err(b.R[k], g.R[k]));
    // the damper: F(damped) - F(undamped) = -c w on the ball's speeds, nothing elsewhere
    VecX Fd, Fb;
    ed.forcing(qb, ub, VecX::Zero(9), Fd);
    eb.forcing(qb, ub, VecX::Zero(9), Fb);
    VecX expected = VecX::Zero(9);
    expected.tail(3) = -0.7 * w;
    worst_damper = std::max(worst_damper, (Fd - Fb - expected).cwiseAbs().maxCoeff() / std::max(1.0, Fb.cwiseAbs().maxCoeff()));
  }
  INFO("ball vs gimbal " << worst << ", damper " << worst_damper);
  CHECK(worst < test::kRoundoff);
  CHECK(worst_damper < test::kRoundoff);
}

namespace {

// The heavy symmetric top: pivot at N's origin, symmetry axis z_B, com at l z_B.
constexpr double kTopMass = 1.5, kTopL = 0.4, kI1 = 0.02, kI3 = 0.035, kG = 9.81;

std::string top_model(const std::string& joint) {
  return fmt::format(R"(name: heavy_top
gravity: [0, 0, {}]
bodies:
  - name: top
    parent: ground
    joint: {}
    mass: {}
    com: [0, 0, {}]
    inertia: [{}, {}, {}, 0, 0, 0]
outputs: [energy, momentum]
)",
                     -kG, joint, kTopMass, kTopL, kI1, kI1, kI3);
}

}  // namespace

TEST_CASE("joints: the heavy top on a ball joint and on a gimbal: same attitude, E and H_z kept, precession at the "
          "closed-form rate",
          "[joints]") {
  // Steady precession at tilt theta about N's x axis with spin w3 about z_B:
  // Omega^2 I1' cos(theta) - Omega I3 w3 + m g l = 0 (I1' = I1 + m l^2 about the pivot), slow root.
  const double theta = 0.5, w3 = 150.0, I1p = kI1 + kTopMass * kTopL * kTopL, mgl = kTopMass * kG * kTopL;
  const double Omega = (kI3 * w3 - std::sqrt(kI3 * kI3 * w3 * w3 - 4 * I1p * std::cos(theta) * mgl)) / (2 * I1p * std::cos(theta));
  // Attitude Rx(theta); angular velocity Omega z_N + psi_dot z_B with the z_B component w3.
  const Mat3 R0 = axis_angle_R<double>(Vec3::UnitX(), theta);
  const Vec3 zN_B = R0.transpose() * Vec3::UnitZ();
  const Vec3 w_B = Omega * zN_B + (w3 - Omega * zN_B.z()) * Vec3::UnitZ();

  const Model ball = load_model(test::write_temp("top_ball.yaml", top_model("{type: ball}")));
  const Model gim = load_model(test::write_temp("top_gimbal.yaml", top_model("{type: gimbal, sequence: xyz}")));
  State sb = initial_state(ball), sg = initial_state(gim);
  const Eigen::Quaterniond q0(R0);
  sb.q << q0.w(), q0.x(), q0.y(), q0.z();
  sb.u = w_B;
  sg.q << theta, 0, 0;  // Rx(theta) Ry(0) Rz(0); Gamma(0) = I, so theta_dot = w_B
  sg.u = w_B;
  const double T = 2 * M_PI / Omega;  // one precession period
  GenericEngine eb(ball), eg(gim);
  IntegratorOptions opt;
  opt.kind = IntegratorKind::rkf78;
  opt.rtol = 1e-11;
  opt.atol = 1e-13;
  auto run = [&](Engine& e, const State& s) {
    std::vector<VecX> xs;
    OdeProblem ode = make_ode_problem(e, s.tau, nullptr);
    VecX x0(e.model().nq + e.model().nu);
    x0 << s.q, s.u;
    integrate(ode, opt, 0.0, x0, T, T / 50, [&](double, const VecX& x) {
      xs.push_back(x);
      return true;
    });
    return xs;
  };
  const std::vector<VecX> xb_all = run(eb, sb), xg_all = run(eg, sg);
  REQUIRE(xb_all.size() == xg_all.size());
  double att = 0, tilt = 0, energy = 0, Hz = 0;
  const EnergyValues E0 = eb.energy(sb.q, sb.u);
  const double Hz0 = eb.momentum(sb.q, sb.u).H_N.z();
  for (std::size_t k = 0; k < xb_all.size(); ++k) {
    const VecX& xb = xb_all[k];
    const VecX& xg = xg_all[k];
    const Eigen::Vector4d qq = xb.head(4).normalized();
    const Mat3 Rb = quat_to_R<double>(qq);
    const Mat3 Rg = axis_angle_R<double>(Vec3::UnitX(), xg(0)) * axis_angle_R<double>(Vec3::UnitY(), xg(1)) *
                    axis_angle_R<double>(Vec3::UnitZ(), xg(2));
    att = std::max(att, (Rb - Rg).cwiseAbs().maxCoeff());
    tilt = std::max(tilt, std::abs(std::acos(Rb(2, 2)) - theta));  // the symmetry axis keeps its tilt
    const EnergyValues E = eb.energy(VecX(qq), VecX(xb.tail(3)));
    energy = std::max(energy, std::abs(E.T + E.V - E0.T - E0.V) / (std::abs(E0.T) + std::abs(E0.V)));
    Hz = std::max(Hz, std::abs(eb.momentum(VecX(qq), VecX(xb.tail(3))).H_N.z() - Hz0) / std::abs(Hz0));
  }
  // the axis turns about z_N at Omega: after one period it is back where it started
  const Eigen::Vector4d q_end = xb_all.back().head(4).normalized();
  const Vec3 z_end = quat_to_R<double>(q_end).col(2);
  const Vec3 z_half = quat_to_R<double>(Eigen::Vector4d(xb_all[25].head(4).normalized())).col(2);
  const double precession_err = std::max((z_end - R0.col(2)).norm(), (z_half - axis_angle_R<double>(Vec3::UnitZ(), M_PI) * R0.col(2)).norm());
  INFO("attitude ball vs gimbal " << att << ", tilt drift " << tilt << ", axis after one period " << precession_err
                                  << ", energy " << energy << ", H_z " << Hz);
  CHECK(att < 1e-8);
  CHECK(tilt < 1e-8);
  CHECK(precession_err < 1e-8);
  CHECK(energy < 1e-10);
  CHECK(Hz < 1e-10);
}

TEST_CASE("joints: generated code equals the generic engine for every new joint (both u-dot forms)", "[joints][jit]") {
  const Model m = load_model(test::write_temp("multidof_gen.yaml", kMultiDof));
  const Model ball = load_model(test::write_temp("ball_gen.yaml", ball_model(false, 0.4)));
  for (const Model* model : {&m, &ball})
    for (const char* form : {"composite", "articulated"}) {
      auto gen = test::generated_engine(*model, form);
      GenericEngine generic(*model);
      const CrosscheckResult r = crosscheck(*gen, generic, 10, 3);
      for (const auto& [what, err] : r.worst) {
        INFO(model->name << " " << form << " " << what << " " << err);
        CHECK(err <= CrosscheckResult::tolerance(what));
      }
    }
}
