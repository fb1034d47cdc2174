// simbody_peer.cpp — a kanegen model (rigid bodies) built in Simbody 3.7, as an
// outside check of kanegen's u̇ and a speed reference.
//
//   simbody_peer MODEL.yaml [--state S.json] [--check REF.json] [--time N]
//
// Prints JSON: u_names and udot in kanegen's conventions, max_rel_diff against a
// `kanegen eval` JSON (--check), ns_per_eval = median wall time of one evaluation
// (--time N): set Q and U, realize to Stage::Acceleration. Exit 0; 1 when the
// difference exceeds --tol (1e-12); 2 when the model or state is refused.
//
// Language: C++17 for this file (Simbody 3.7's headers are not C++20-clean).
//
// Translation (see NOTES.md for the derivations). Each kanegen body is one
// MobilizedBody whose inboard frame F sits in the parent at X_PF and whose outboard
// frame M sits in the body at X_BM:
//   * revolute -> Pin, which turns about the common z axis of F and M. With R_A a
//     rotation taking z to our axis a (a = R_A z): X_PF = (R_PJ R_A, p_PJ),
//     X_BM = (R_A, 0). Then R_PB = R_PJ R_A Rz(θ) R_Aᵀ = R_PJ Rot(a, θ), origin p_PJ,
//     q = θ, u = θ̇: exactly dynamics.md's table.
//   * prismatic -> Slider (along the common x axis), the same with R_A x = a:
//     R_PB = R_PJ, origin p_PJ + R_PJ a s, q = s, u = ṡ.
//   * cylindrical -> Cylinder (common z, R_A z = a); q = (angle, disp) as ours.
//   * universal -> Universal (x, then the new y): R_A = [a1 a2 a1×a2] for
//     orthogonal axes; gimbal -> Gimbal (body-fixed x, y, z): R_A = [a1 a2 a1×a2],
//     a left-handed triple (a1×a2 = -a3) with its third angle negated. Non-orthogonal axes are refused
//     (Simbody has no mobilizer with those coordinates).
//   * planar -> Planar (F = J): Simbody's q = (angle, x, y), ours (x, y, angle).
//   * ball -> Ball (F = J, M = B): Simbody's u is ω_FM in F, ours ω_B:
//     u_F = R_FM ω_B; the quaternion is set by fitting R(quat).
//   * fixed -> Weld with X_PF = (R_PJ, p_PJ), X_BM = identity.
//   * free -> Free with X_PF = (R_PJ, p_PJ), X_BM = identity (so F = J, M = B):
//     q = [quat_FM (w x y z), p_FM], u = [ω_FM, v_FM] both in F: converted below.
//   * springs/dampers: Force::MobilityLinearSpring (k, rest) and
//     MobilityLinearDamper (c) on the mobility; gravity: Force::Gravity.
//   * mass properties: Simbody wants the inertia about the BODY ORIGIN:
//     I_O = I_cm + m (|c|² E − c cᵀ).
//
// Build note: Debian's Simbody 3.7 is compiled WITHOUT NDEBUG, and its headers have
// debug-only code; this file must be compiled with NDEBUG undefined (CMakeLists.txt
// adds -UNDEBUG for this target), or the program crashes. It must also not share a
// process with SUNDIALS 6 (libSimTKmath exports its own old N_V* symbols).
#ifdef NDEBUG
#error "simbody_peer.cpp must be compiled with NDEBUG undefined (Debian's Simbody is a non-NDEBUG build)"
#endif

#include "peer_model.hpp"

#include <Simbody.h>
#include <fmt/format.h>

namespace {

using namespace peers;

SimTK::Vec3 to_simtk(const Vector3d& v) { return {v(0), v(1), v(2)}; }

/// A proper rotation computed in double by us: handed to Simbody as it is
/// (the "trusted" constructor; the other one re-orthogonalizes).
SimTK::Rotation to_simtk_rotation(const Matrix3d& R) {
  SimTK::Mat33 M;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) M(i, j) = R(i, j);
  return SimTK::Rotation(M, true);
}
SimTK::Transform transform(const Matrix3d& R, const Vector3d& p) {
  return SimTK::Transform(to_simtk_rotation(R), to_simtk(p));
}

/// Mass properties with the inertia about the body origin (Simbody's convention).
SimTK::MassProperties mass_properties(const peers::Body& b) {
  const Vector3d& c = b.com_B;
  const Matrix3d I_O = b.I_Bcm_B + b.mass * (c.squaredNorm() * Matrix3d::Identity() - c * c.transpose());
  SimTK::Mat33 M;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) M(i, j) = I_O(i, j);
  return SimTK::MassProperties(b.mass, to_simtk(c), SimTK::Inertia(M));
}

/// How our speeds k = 0..nu-1 of a joint sit among Simbody's mobilities of the
/// same mobilizer: Simbody's u[index[k]] = sign[k] * our u[k] (also q; a ball's
/// and a free joint's speeds are rotated instead, below).
struct Map {
  std::vector<int> index;
  std::vector<double> sign;
};

/// Columns of a right-handed frame R_A for a sequence of mutually orthogonal
/// rotation axes (a1, a2[, a3]) that Simbody's Universal (x, then the new y) or
/// Gimbal (x, new y, new z) turns about: R_A x = a1, R_A y = a2, R_A z = a1×a2 =
/// ±a3 (sign returned: Rot(a3, q3) = Rot(R_A z, sign q3)). Refused when the axes
/// are not orthogonal: those have no Simbody mobilizer of the same coordinates.
std::pair<Matrix3d, double> orthogonal_frame(const peers::Body& b) {
  const Vector3d a1 = b.motions[0].axis, a2 = b.motions[1].axis;
  constexpr double tol = 1e-12;
  if (std::abs(a1.dot(a2)) > tol)
    throw Refused("body '" + b.name + "': Simbody has no mobilizer for non-orthogonal joint axes");
  Matrix3d R_A;
  R_A.col(0) = a1;
  R_A.col(1) = a2;
  R_A.col(2) = a1.cross(a2);
  double sign = 1;
  if (b.motions.size() == 3) {
    const double c = b.motions[2].axis.dot(R_A.col(2));
    if (std::abs(std::abs(c) - 1) > tol)
      throw Refused("body '" + b.name + "': Simbody's Gimbal turns about three orthogonal axes (x, y, z)");
    sign = c > 0 ? 1 : -1;
  }
  return {R_A, sign};
}

Map mobility_map(const peers::Body& b) {
  switch (b.joint) {
    case JointType::planar: return {{1, 2, 0}, {1, 1, 1}};  // Simbody: (angle, x, y)
    case JointType::gimbal: return {{0, 1, 2}, {1, 1, orthogonal_frame(b).second}};
    default: {
      Map m;
      for (int k = 0; k < b.nu; ++k) {
        m.index.push_back(k);
        m.sign.push_back(1);
      }
      return m;
    }
  }
}

/// The Simbody mobilizer of one kanegen joint, with its frames F (in the parent,
/// X_PF) and M (in the body, X_BM) chosen so that R_PB and the body origin follow
/// dynamics.md's joint table for every q.
SimTK::MobilizedBody mobilizer(const peers::Body& b, SimTK::MobilizedBody& parent, const SimTK::Body::Rigid& info) {
  using namespace SimTK;
  auto frames = [&](const Matrix3d& R_A) {
    return std::pair{transform(b.R_PJ * R_A, b.p_PJ), transform(R_A, Vector3d::Zero())};
  };
  switch (b.joint) {
    case JointType::revolute: {
      const auto [X_PF, X_BM] = frames(frame_with_axis(b.motions[0].axis, 2));  // R_A z = a
      return MobilizedBody::Pin(parent, X_PF, info, X_BM);
    }
    case JointType::prismatic: {
      const auto [X_PF, X_BM] = frames(frame_with_axis(b.motions[0].axis, 0));  // R_A x = a
      return MobilizedBody::Slider(parent, X_PF, info, X_BM);
    }
    case JointType::cylindrical: {
      const auto [X_PF, X_BM] = frames(frame_with_axis(b.motions[0].axis, 2));  // R_A z = a
      return MobilizedBody::Cylinder(parent, X_PF, info, X_BM);
    }
    case JointType::universal: {
      const auto [X_PF, X_BM] = frames(orthogonal_frame(b).first);
      return MobilizedBody::Universal(parent, X_PF, info, X_BM);
    }
    case JointType::gimbal: {
      // R_A stays proper: a left-handed triple turns about R_A z = -a3 (sign: Map).
      const auto [X_PF, X_BM] = frames(orthogonal_frame(b).first);
      return MobilizedBody::Gimbal(parent, X_PF, info, X_BM);
    }
    case JointType::planar: {
      const auto [X_PF, X_BM] = frames(Matrix3d::Identity());
      return MobilizedBody::Planar(parent, X_PF, info, X_BM);
    }
    case JointType::ball: {
      const auto [X_PF, X_BM] = frames(Matrix3d::Identity());
      return MobilizedBody::Ball(parent, X_PF, info, X_BM);
    }
    case JointType::fixed: return MobilizedBody::Weld(parent, transform(b.R_PJ, b.p_PJ), info, Transform());
    case JointType::free: return MobilizedBody::Free(parent, transform(b.R_PJ, b.p_PJ), info, Transform());
  }
  throw Refused("body '" + b.name + "': unhandled joint type");
}

class SimbodyPeer {
 public:
  explicit SimbodyPeer(const Model& model) : model_(model), matter_(system_), forces_(system_) {
    using namespace SimTK;
    if (model.gravity_N.norm() > 0) Force::Gravity(forces_, matter_, to_simtk(model.gravity_N));
    for (const peers::Body& b : model.bodies) {
      MobilizedBody& parent = b.parent < 0 ? matter_.updGround() : mobod_[b.parent];
      const SimTK::Body::Rigid info(mass_properties(b));
      mobod_.push_back(mobilizer(b, parent, info));
      // Springs and dampers on Simbody's mobilities (sign and order of ours: Map).
      const Map map = mobility_map(b);
      for (int k = 0; k < b.nu && b.joint != JointType::free; ++k) {
        const int mob = map.index[k];
        const double sign = map.sign[k];
        if (b.stiffness[k] != 0)
          Force::MobilityLinearSpring(forces_, mobod_.back(), mob, b.stiffness[k], sign * b.rest[k]);
        if (b.damping[k] != 0) Force::MobilityLinearDamper(forces_, mobod_.back(), mob, b.damping[k]);
      }
    }
    system_.realizeTopology();
    state_ = system_.getDefaultState();
    if (state_.getNU() != model.nu)
      throw Refused(fmt::format("Simbody has {} mobilities, kanegen {}", state_.getNU(), model.nu));
  }

  /// Writes our (q, u) into Simbody's Q, U (and keeps copies for the timing loop).
  ///
  /// Free joint (F = J, M = B; R_FM = R(quat)):
  ///   Q = [qw qx qy qz, x y z]      the same quaternion and translation as ours
  ///   U = [R_FM ω_B, R_FM v_B]       Simbody's ω_FM, v_FM are in F components
  void set_state(const State& s) {
    using namespace SimTK;
    for (std::size_t i = 0; i < model_.bodies.size(); ++i) {
      const peers::Body& b = model_.bodies[i];
      if (b.joint == JointType::ball) {
        const auto q = s.q.segment<4>(b.q_index);  // normalized
        mobod_[i].setQToFitRotation(state_, to_simtk_rotation(rotation_from_quaternion(q(0), q(1), q(2), q(3))));
        const Vector3d w_F = rotation_from_quaternion(q(0), q(1), q(2), q(3)) * s.u.segment<3>(b.u_index);
        for (int k = 0; k < 3; ++k) mobod_[i].setOneU(state_, k, w_F(k));
      } else if (b.joint != JointType::free) {
        const Map map = mobility_map(b);
        for (int k = 0; k < b.nu; ++k) {
          mobod_[i].setOneQ(state_, map.index[k], map.sign[k] * s.q(b.q_index + k));
          mobod_[i].setOneU(state_, map.index[k], map.sign[k] * s.u(b.u_index + k));
        }
      } else {
        const auto& free = MobilizedBody::Free::downcast(mobod_[i]);
        const auto q = s.q.segment<7>(b.q_index);  // x y z qw qx qy qz, quaternion normalized
        free.setQ(state_, Vec7(q(3), q(4), q(5), q(6), q(0), q(1), q(2)));
        const Matrix3d R_FM = rotation_from_quaternion(q(3), q(4), q(5), q(6));
        const Vector3d w_F = R_FM * s.u.segment<3>(b.u_index + 3), v_F = R_FM * s.u.segment<3>(b.u_index);
        free.setU(state_, Vec6(w_F(0), w_F(1), w_F(2), v_F(0), v_F(1), v_F(2)));
      }
    }
    q_ = state_.getQ();
    u_ = state_.getU();
  }

  /// One evaluation: what --time measures. Setting Q invalidates every stage from
  /// Position on, so realize() recomputes kinematics, forces and u̇ from scratch.
  void evaluate() {
    state_.updQ() = q_;
    state_.updU() = u_;
    system_.realize(state_, SimTK::Stage::Acceleration);
  }

  /// Simbody's u̇ in kanegen's conventions (after set_state and evaluate, same s).
  ///
  /// Free joint: v_B = R_FMᵀ v_F and Ṙ_FM = R_FM [ω_B]× give
  ///   v̇_B = R_FMᵀ v̇_F − ω_B × v_B,   ω̇_B = R_FMᵀ ω̇_F  (ω_B × ω_B = 0).
  VectorXd udot(const State& s) const {
    using namespace SimTK;
    VectorXd ud(model_.nu);
    for (std::size_t i = 0; i < model_.bodies.size(); ++i) {
      const peers::Body& b = model_.bodies[i];
      if (b.joint == JointType::ball) {
        // u_F = R_FM ω_B, Ṙ_FM = R_FM [ω_B]×:  ω̇_B = R_FMᵀ u̇_F (ω_B × ω_B = 0).
        const auto q = s.q.segment<4>(b.q_index);
        const Vector3d wdot_F(mobod_[i].getOneUDot(state_, 0), mobod_[i].getOneUDot(state_, 1),
                              mobod_[i].getOneUDot(state_, 2));
        ud.segment<3>(b.u_index) = rotation_from_quaternion(q(0), q(1), q(2), q(3)).transpose() * wdot_F;
      } else if (b.joint != JointType::free) {
        const Map map = mobility_map(b);
        for (int k = 0; k < b.nu; ++k) ud(b.u_index + k) = map.sign[k] * mobod_[i].getOneUDot(state_, map.index[k]);
      } else {
        const auto& free = MobilizedBody::Free::downcast(mobod_[i]);
        const Vec6& a = free.getUDot(state_);
        const auto q = s.q.segment<7>(b.q_index);
        const Matrix3d R_FM = rotation_from_quaternion(q(3), q(4), q(5), q(6));
        const Vector3d wdot_F(a[0], a[1], a[2]), vdot_F(a[3], a[4], a[5]);
        const Vector3d v_B = s.u.segment<3>(b.u_index), w_B = s.u.segment<3>(b.u_index + 3);
        ud.segment<3>(b.u_index) = R_FM.transpose() * vdot_F - w_B.cross(v_B);
        ud.segment<3>(b.u_index + 3) = R_FM.transpose() * wdot_F;
      }
    }
    return ud;
  }

 private:
  const Model& model_;
  SimTK::MultibodySystem system_;
  SimTK::SimbodyMatterSubsystem matter_;
  SimTK::GeneralForceSubsystem forces_;
  std::vector<SimTK::MobilizedBody> mobod_;  ///< handles, one per kanegen body (same index)
  SimTK::State state_;
  SimTK::Vector q_, u_;  ///< the state in Simbody's ordering, for the timing loop
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"kanegen model -> Simbody 3.7: u-dot in kanegen conventions, check and timing"};
  Options opt;
  add_options(app, opt);
  CLI11_PARSE(app, argc, argv);
  try {
    const Model model = load_model(opt.model);
    const State s = load_state(model, opt.state);
    SimbodyPeer peer(model);
    peer.set_state(s);
    peer.evaluate();
    const VectorXd ud = peer.udot(s);
    return finish(opt, model, "simbody", ud, [&] { peer.evaluate(); });
  } catch (const Refused& e) {
    std::cerr << "simbody_peer: refused: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {  // SimTK::Exception::Base derives from std::exception
    std::cerr << "simbody_peer: error: " << e.what() << "\n";
    return 1;
  }
}
