// The symbolic counterpart of dynamics/workspace.hpp: the per-body
// quantities of Kane's method for one Model as expressions bound in one
// Program, under the same names and frames as the generic engine
// (w_B, v_O_B, R_NB, ...), and the context every symbolic pass works in.
//
// The passes, one file each, mirror dynamics/:
//   kinematics.cpp            outward pass: orientations, velocities, remainder accelerations
//   body_terms.cpp            per-body generalized mass M_body, velocity terms h, gravity g
//   spatial_transforms.cpp    motion subspaces S_j and the parent <-> child transforms Xe_j
//   forcing.cpp               F = tau + elastic + S^T W, inward pass (O(n))
//   composite_inertia.cpp     M by composite inertias and column walks (O(n d))
//   tree_ldlt.cpp             M u_dot = F by L^T D L along the dof tree (no fill-in)
//   articulated_body.cpp      u_dot by the articulated-body recursion (O(n))
//   reactions.cpp             inward Newton-Euler pass with the accelerations
//   invariants.cpp            T, V, p_N, H_N
//   kinematic_equations.cpp   q_dot = W(q) u
// Body velocity coordinates are z_j = [v_O_B, w_B, eta_dot] (B components), as
// in dynamics/body_inertia.hpp, which the generated code is checked against.
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

#include "codegen/constants.hpp"
#include "codegen/joint_frames.hpp"
#include "codegen/symbolic.hpp"
#include "model/model.hpp"
#include "model/parameters.hpp"

#include <optional>

namespace kanegen::codegen {

/// One mass element of a body for the central field (dynamics/central_gravity.hpp):
/// the rigid part or a node, at s_B (B components, displaced), with the
/// partials of s_B (Pt) and of its small rotation (H) w.r.t. the body's modal
/// coordinates, and its inertia about s_B in B axes (node frame turned).
struct SymMassElement {
  ex mass;
  SV3 s_B;
  std::vector<SV3> Pt, H;  ///< empty: no modal partials (the rigid part; a node without rotary inertia has no H)
  SM3 I_B;
  bool has_inertia = false;
};

struct SymBodyWorkspace {
  SM3 R_PB, R_NB;                 ///< orientation of B in its parent, in N
  SM3 R_PJ, R_JB;                 ///< R_PB = R_PS R_PJ R_JB: joint frame in the parent (with a node's turn), B in J
  /// The first turn from the parent, about its z axis (a revolute child other than the parent's main child,
  /// joint_frames.hpp), when `screw`: R_PJ is then the joint frame in these turned axes S (Rx(alpha))
  SM3 R_PS;
  bool screw = false;
  SV3 p_PO_P;                     ///< O_B from the parent's origin, parent components
  SV3 p_BP_J;                     ///< O_B from the parent's origin, J components
  SV3 r_NO_N;                     ///< O_B from N's origin, N components
  SV3 w_B, v_O_B;                 ///< angular velocity, velocity of O_B (B components)
  SV3 a_R_B, alpha_R_B;           ///< remainder accelerations (B components)
  std::vector<ex> eta, eta_dot;   ///< modal coordinates and speeds
  /// Partials of [v_O_B; w_B] w.r.t. the parent's modal speeds, one 6-vector per
  /// parent mode (a child attached at a node of a flexible parent).
  std::vector<std::array<ex, 6>> P_node;
  /// A joint formed by the joint module (model/joints/joint_kinematics.hpp:
  /// universal, gimbal, cylindrical, planar, ball): its motion subspace, one
  /// [linear; angular] 6-vector per speed in B components (q-dependent).
  std::vector<std::array<ex, 6>> S_joint;
  SMat M_body;                    ///< (6+m)^2 generalized mass in z
  std::vector<ex> h_body, g_body; ///< 6+m velocity terms, generalized gravity
  std::vector<SymMassElement> elements;  ///< with central gravity only (compute_body_terms)
};

/// One Model's symbolic formulation in one Program.
struct KaneContext {
  KaneContext(const Model& model, Program& program, Constants& constants, const StateSymbols& x)
      : model(model), P(program), C(constants), x(x), A(program), body(model.bodies.size()) {
    program.fold = [&constants](const ex& e) { return constants.fold(e); };
  }
  /// The context of a model with the generator's frames (joint_frames.hpp).
  KaneContext(const FramedModel& framed, Program& program, Constants& constants, const StateSymbols& x)
      : KaneContext(framed.model, program, constants, x) {
    angle_offset = framed.angle_offset;
    R_BBp = framed.R_BBp;
    screw_angle = framed.screw_angle;
  }

  const Model& model;
  Program& P;
  Constants& C;
  const StateSymbols& x;
  Alg A;
  std::vector<SymBodyWorkspace> body;
  std::map<int, std::array<ex, 3>> motion_symbols;  ///< body -> f, f_dot, f_ddot (see motion())
  /// Per body: a revolute joint turns by q + angle_offset[j] (joint_frames.hpp); empty: no offsets.
  std::vector<double> angle_offset;
  /// Per body: its joint frame turned from the parent's by Rz(screw_angle[j]) first (joint_frames.hpp); empty: none.
  std::vector<double> screw_angle;
  /// Per body: axes of the generator's frame B' in the model's frame B
  /// (joint_frames.hpp), for the runtime parameters given in B; empty: identity.
  std::vector<Mat3> R_BBp;
  /// Gravity as a fictitious acceleration -g of the ground (Featherstone): with
  /// velocities, every body's remainder acceleration carries -g and no body has
  /// a gravity term g_body, so no R_NB is needed for the dynamics.
  bool gravity_in_base_acceleration = true;

  /// A named model constant (constants.hpp) of the current group.
  ex c(double v, const std::string& name, const std::string& unit, const std::string& what) {
    return C.value(v, name, unit, what);
  }
  SV3 cvec(const Vec3& v, const std::string& name, const std::string& unit, const std::string& what);
  SM3 cmat(const Mat3& m, const std::string& name, const std::string& unit, const std::string& what,
           bool symmetric = false);
  /// The runtime parameter prm[k] of this kind, body and index
  /// (model/parameters.hpp), or nullopt when the value is folded as a constant.
  std::optional<ex> param(ParameterKind kind, int body, int index) const {
    const int k = find_parameter(model.parameters, kind, body, index);
    return k >= 0 ? std::optional<ex>(x.params[k]) : std::nullopt;
  }
  /// Gravity in N components (runtime parameters or named constants), times `sign`.
  SV3 gravity(double sign, const std::string& name, const std::string& what);
  /// Whether gravity may be non-zero (a runtime parameter, or a non-zero constant).
  bool has_gravity() const {
    return !model.g_N.isZero() || find_parameter(model.parameters, ParameterKind::gravity, -1, 0) >= 0 ||
           find_parameter(model.parameters, ParameterKind::gravity, -1, 1) >= 0 ||
           find_parameter(model.parameters, ParameterKind::gravity, -1, 2) >= 0;
  }
  /// Central gravity (gravity: central:): mu and J2 as runtime parameters or named constants.
  bool has_central() const { return model.central.has_value(); }
  ex central_mu();
  ex central_J2();
  /// Name of a quantity of body j for the emitted code, e.g. "w_B_ant2".
  std::string name(const std::string& quantity, int j) const { return quantity + "_" + model.bodies[j].name; }
  /// The prescribed coordinate of body j's joint and its two derivatives at t
  /// (symbols f_<body>, f_dot_<body>, f_ddot_<body>, defined by a prelude of
  /// the Program that calls the motion's helper of the emitted support code).
  std::array<ex, 3> motion(int j);
};

// ---- passes (one file each, see the header comment) ----------------------

/// Outward pass; velocities and remainder accelerations only when
/// `with_velocity` (M needs none).
void compute_kinematics(KaneContext& ctx, bool with_velocity);
/// Body inertia, velocity and gravity terms (after compute_kinematics).
void compute_body_terms(KaneContext& ctx, bool with_velocity);
/// The central field's generalized forces on body j's velocity coordinates,
/// added to its g_body, from its mass elements (central_gravity.cpp).
void add_central_gravity_forces(KaneContext& ctx, int j);
/// The central field's potential of body j's mass elements.
ex central_potential(KaneContext& ctx, int j);
/// The central field's acceleration at a point r (N components): point mass and J2.
SV3 central_field_at(KaneContext& ctx, const SV3& r_N);
/// compute_kinematics then compute_body_terms: what every dynamics function starts with.
inline void prepare(KaneContext& ctx, bool with_velocity) {
  compute_kinematics(ctx, with_velocity);
  compute_body_terms(ctx, with_velocity);
}

/// Columns of u that body j owns (its joint's, then its modes'), ascending.
std::vector<int> own_columns(const Model& model, int j);
/// Motion subspace S of body j: its own columns as (6+m)-vectors of z_j.
std::vector<std::vector<ex>> motion_subspace(KaneContext& ctx, int j);
/// Xe_j applied to the parent's (6 + m_p) motion: the first 6 rows of body
/// j's (6 + m_j) motion (the rest zero); all zero for a root (dp null).
std::vector<ex> transform_motion_from_parent(KaneContext& ctx, int j, const std::vector<ex>* dp);
/// Xe_j^T applied to a 6-vector wrench of body j: the parent's (6 + m_p) contribution.
std::vector<ex> transform_wrench_to_parent(KaneContext& ctx, int j, const std::vector<ex>& W6);
/// R J R^T of a symmetric J (symmetric result, each product bound).
SM3 rotate_symmetric(KaneContext& ctx, const SM3& R, const SM3& J);
/// R B R^T.
SM3 rotate_matrix(KaneContext& ctx, const SM3& R, const SM3& B);
/// Xe^T I Xe for a symmetric 6 x 6 I of body j whose joint is not at a node of
/// a flexible parent: the parent's 6 x 6 (turn by R_JB, shift, turn by R_PJ).
SMat transform_inertia_to_parent(KaneContext& ctx, int j, const SMat& I);
/// y_j = g_j - h_j - M_body z_R for every body (generalized gravity and
/// velocity forces with the remainder accelerations' inertia forces).
std::vector<std::vector<ex>> compute_bias_forces(KaneContext& ctx);
/// Stiffness, damping and rest value of body j's joint spring (runtime parameters or constants).
/// Spring stiffness, damping and rest of coordinate k of body j's joint (runtime
/// parameters or named constants).
std::array<ex, 3> joint_spring(KaneContext& ctx, int j, int k);
/// Modal stiffness K and damping D of body j's mode i (from runtime frequency
/// and damping ratio parameters when given: K = w^2 Y, D = 2 zeta w Y).
std::array<ex, 2> modal_stiffness_damping(KaneContext& ctx, int j, int i);
/// tau + spring/damper or modal stiffness/damping of body j's own speed `own`.
ex applied_force(KaneContext& ctx, int j, int own);

std::vector<ex> compute_forcing(KaneContext& ctx);
SMat compute_mass_matrix(KaneContext& ctx);
/// Solves M x = b by L^T D L along the dof tree; returns x and binds the pivots D_ii
/// in `pivots` (index = speed).
/// A pivot of the generated factorization below this fraction of its
/// diagonal entry counts as zero (as the generic engine's cond(M) > 1e14).
inline constexpr const char* kPivotRatio = "1e-14";

/// pivot_scales[k]: M's diagonal entry k, against which pivot k is judged
/// (a pivot below kPivotRatio of it means dof k is, to round-off, a
/// combination of its descendants': M is singular there).
std::vector<ex> solve_tree_ldlt(KaneContext& ctx, SMat M, std::vector<ex> b, std::vector<ex>& pivots,
                                std::vector<ex>& pivot_scales);
/// u_dot by the articulated-body recursion (O(n)); `pivots[r]` is the pivot
/// of speed r in its joint's D matrix factorization.
std::vector<ex> compute_udot_articulated(KaneContext& ctx, std::vector<ex>& pivots, std::vector<ex>& pivot_scales);
/// 6 entries per body: reaction [force; torque about O_B] (B components).
/// `accelerations`, if given, receives each body's accelerations [a_O_B,
/// alpha_B, eta_ddot] (with gravity as a base acceleration: a_O_B - g_B).
std::vector<ex> compute_reactions(KaneContext& ctx, const std::vector<ex>& udot,
                                  std::vector<std::vector<ex>>* accelerations = nullptr);
/// The generalized forces of the named inputs on body j's velocity
/// coordinates (6 + m): [force; torque about O_B] in B components, then the
/// modal forces of inputs at its nodes (inputs_outputs.cpp).
std::vector<ex> input_wrench(KaneContext& ctx, int j);
/// The joint-torque inputs on body j's joint speed.
ex joint_input(KaneContext& ctx, int j, int own);
/// Assigns y[...] = the model's sensors, from the reactions (6 per body) and
/// the bodies' accelerations of compute_reactions.
void assign_sensor_outputs(KaneContext& ctx, const std::vector<ex>& wrenches,
                           const std::vector<std::vector<ex>>& accelerations, const std::string& y);
/// Support code of the attitude outputs (quaternion from a rotation matrix).
std::string attitude_support_code();
/// atan2 of dual numbers; templates/orbit_frame.inc follows it in the header (assembler.cpp).
std::string orbit_frame_support_code();
ex compute_kinetic_energy(KaneContext& ctx);
ex compute_potential_energy(KaneContext& ctx);
/// p_N[3], H_N[3]
/// A body's first moment of mass about O_B, B components, from M_body's rows 3-5 (S^x).
SV3 first_moment_B(const SymBodyWorkspace& s);
std::vector<ex> compute_momentum(KaneContext& ctx);
std::vector<ex> compute_qdot(KaneContext& ctx);

}  // namespace kanegen::codegen
