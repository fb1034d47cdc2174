// The read-only description of a multibody system: tree topology, joints,
// mass data (rigid part and modal data of flexible bodies), forces, initial
// state and requested outputs. Built once by load_model() (engine/load_model.hpp)
// and never modified by the engines; all per-evaluation data lives in a
// Workspace (workspace.hpp).
//
// Conventions (../shared/spec/dynamics.md):
//   - B_j: body frame, origin O_j at the inboard joint point.
//   - R_PJ: joint frame orientation in parent components (x_P = R_PJ x_J).
//   - Vectors carry the frame of their components as a suffix: p_PJ (in P).
#pragma once

#include <Eigen/Dense>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "model/events.hpp"
#include "model/inputs_outputs.hpp"
#include "model/runtime_parameter.hpp"
#include "model/modal_integrals.hpp"
#include "model/orbit.hpp"
#include "model/prescribed_motion.hpp"
#include "model/joints/joint.hpp"
#include "model/joints/joint_traits.hpp"

namespace kanegen {

using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;

const char* to_string(JointType t);

/// Number of generalized coordinates / speeds the joint contributes (0 for a
/// prescribed joint): its traits' (model/joints/joint_traits.hpp).
int joint_nq(const Joint& j);
int joint_nu(const Joint& j);

/// Rigid part of a body: moves with B. Mass may be zero.
struct RigidPart {
  double mass = 0.0;
  Vec3 com_B = Vec3::Zero();        ///< centre of mass from O, B components
  Mat3 I_c_B = Mat3::Zero();        ///< inertia about the com, B axes
};

/// One node of a lumped-mass FEA model.
struct ModalNode {
  int id = 0;                       ///< id in the modal data file
  Vec3 rho_B = Vec3::Zero();        ///< undeformed position from O, B components
  double mass = 0.0;
  Mat3 J_B = Mat3::Zero();          ///< rotary inertia in B axes at eta = 0 (turns with the node frame)
};

/// Modal description of a flexible body, modes already selected and
/// mass-normalized (Sum_k m_k t_k.t_k + r_k^T J_k r_k = 1 for each kept mode).
/// Node k's displaced position is rho_k + Phi_k eta + 1/2 gamma_k(eta), with
/// gamma_k = [eta^T Gamma_k[0] eta, eta^T Gamma_k[1] eta, eta^T Gamma_k[2] eta]
/// (foreshortening, dynamics.md), and its node frame is C(Psi_k eta).
struct FlexibleData {
  std::string source;               ///< modal file path or "beam" (for messages)
  std::vector<ModalNode> nodes;
  MatX Phi;                         ///< 3*nodes x m: translational shapes, node k rows 3k..3k+2
  MatX Psi;                         ///< 3*nodes x m: rotational shapes
  VecX frequency_hz;                ///< m natural frequencies (clamped at O)
  VecX damping_ratio;               ///< m modal damping ratios
  VecX K;                           ///< m diagonal modal stiffness (2 pi f)^2 Y_ii
  VecX D;                           ///< m diagonal modal damping 2 zeta (2 pi f) Y_ii
  /// Per node: Gamma_k along B's x, y, z (m x m, symmetric); a node without
  /// second-order data (or a body with foreshortening off) has 0 x 0 matrices.
  std::vector<std::array<MatX, 3>> Gamma;
  int modes() const { return static_cast<int>(Phi.cols()); }
  int node_index(int id) const;     ///< -1 if no node with that id
  /// Whether node k has second-order (foreshortening) data.
  bool has_second_order(int k) const {
    return k < static_cast<int>(Gamma.size()) && (Gamma[k][0].size() || Gamma[k][1].size() || Gamma[k][2].size());
  }
  /// Whether node k is handled element by element (rotary inertia or
  /// foreshortening); the others enter the body through its mass integrals.
  bool node_is_rich(int k) const { return has_second_order(k) || !nodes[k].J_B.isZero(0.0); }
};

struct Body {
  std::string name;
  int line = 0;                     ///< line of the body's entry in the model file (0: built in code)
  int parent = -1;                  ///< index of the parent body, -1 for ground
  std::vector<int> children;
  Joint joint;
  /// The joint's motions from J to B (its traits' primitives(joint)), formed once by finalize_model.
  std::vector<JointPrimitive> primitives;
  RigidPart rigid;
  std::optional<FlexibleData> flex;
  BodyMassIntegrals integrals;      ///< mass data of the rigid part and the plain nodes (modal_integrals.hpp)
  /// Nodes handled one by one (FlexibleData::node_is_rich: rotary inertia or
  /// foreshortening), ascending; the other nodes are in `integrals`.
  std::vector<int> rich_nodes;
  double total_mass = 0.0;          ///< rigid part and every node

  // Layout in the state vectors.
  int q_joint = 0;                  ///< first joint coordinate in q
  int u_joint = 0;                  ///< first joint speed in u
  int q_eta = 0;                    ///< first modal coordinate in q
  int u_eta = 0;                    ///< first modal speed in u
  int n_modes() const { return flex ? flex->modes() : 0; }
  /// Speeds that move this body: those of its joint and modes and of all its
  /// ancestors (its kinematic chain), ascending. The partial velocities of the
  /// body are zero in every other column.
  std::vector<int> chain_u;
};

/// A central gravity field (dynamics.md, "Forces"): mu (m^3/s^2) > 0; J2 and radius (m) optional, together.
struct CentralGravity {
  double mu = 0.0;
  double J2 = 0.0;
  double radius = 0.0;
};

struct Outputs {
  bool energy = false;
  bool momentum = false;
  bool reactions = false;
};

struct Model {
  std::string name;
  std::string description;
  std::string source_path;          ///< the YAML file it was read from
  Vec3 g_N = Vec3::Zero();          ///< uniform gravity, N components (zero with a central field)
  /// `gravity: {central: ...}` (model-format.md, "Gravity"): the central body at N's origin, J2 about N's z.
  std::optional<CentralGravity> central;
  /// `initial: orbit:` as given, and the free root body it places (model/initial_orbit.hpp): q0 and u0 hold
  /// the placed state; a sweep places each run again with its own masses and dispersed elements.
  std::optional<InitialOrbit> initial_orbit;
  int orbit_root = -1;
  std::vector<Body> bodies;         ///< parents before children
  int nq = 0;
  int nu = 0;
  std::vector<std::string> q_names;
  std::vector<std::string> u_names;
  /// Per speed: its name before 2026-12-01 (a coordinate's rate had the
  /// coordinate's name), or "" where it is the same; accepted on input where
  /// a speed is named (model-format.md, Joints).
  std::vector<std::string> legacy_u_names;
  /// Unit quaternions in q (free and ball joints): where each sits and the
  /// angular speeds that turn it, in body order (JointTraits::quaternion).
  struct QuaternionSlot {
    int body = -1;
    int q = 0;  ///< q index of its w component
    int u = 0;  ///< u index of the first of its three angular speeds (B components)
  };
  std::vector<QuaternionSlot> quaternions;
  /// Bodies whose joints can reach gimbal lock (JointTraits::can_lock_up, not
  /// prescribed), in body order.
  std::vector<int> lockable_joints;
  VecX q0;                          ///< initial coordinates (quaternions unit)
  VecX u0;                          ///< initial speeds
  Outputs outputs;
  /// Named inputs (docs/gnc.md): the vector w of nw scalars named input_names.
  std::vector<Input> inputs;
  int nw = 0;
  std::vector<std::string> input_names;
  /// Named outputs (sensors): the vector y of ny scalars named output_names.
  std::vector<Sensor> sensors;
  int ny = 0;
  std::vector<std::string> output_names;
  /// Runtime parameters (model/parameters.hpp): kept symbolic by the
  /// generator; scalar entries, nominal values from the model.
  std::vector<RuntimeParameter> parameters;
  /// Events that lock and release joints during a run (model/events.hpp), in file order.
  std::vector<Event> events;

  int body_index(const std::string& name) const;  ///< -1 if absent
  int q_index(const std::string& name) const;     ///< -1 if absent
  int u_index(const std::string& name) const;     ///< -1 if absent (current names only)
  /// A speed named in a speed context: its current name, or its older name
  /// (legacy_u_names); -1 if neither.
  int speed_index(const std::string& name) const;
  int input_index(const std::string& name) const; ///< entry of w, -1 if absent
  int output_index(const std::string& name) const;///< entry of y, -1 if absent
  /// Coordinates of the prescribed joints, named as the joint coordinate
  /// would be ("hub.angle", "cart.disp"), in body order.
  std::vector<std::string> prescribed_names;

  bool has_flexible() const;
  bool has_prescribed() const { return !prescribed_names.empty(); }
};

/// Relative size below which a model constant is a round-off residue of an
/// exact value (docs/decisions.md): a few ulps of the largest entry of its
/// vector or matrix.
inline constexpr double kRoundoffResidue = 1e-14;

/// Snaps the round-off residues of exact values in a body's geometry to the
/// exact values, so that the generator sees the model's sparsity: in a joint
/// rotation or axis (unit quantities), entries within kRoundoffResidue of 0
/// or +-1 become 0 or +-1 (e.g. the 6.1e-17 and 2.2e-16 of rpy(pi/2)); in a
/// position, com or inertia, entries at most kRoundoffResidue times the
/// largest entry of the same vector (inertia: its largest diagonal) become 0.
/// Changes the dynamics by less than the rounding of its own evaluation.
void snap_roundoff_residues(Body& body);
/// A rotation's (or unit vector's) entries within kRoundoffResidue of 0, 1 or -1 set to them.
void snap_unit_residues(Mat3& R);
/// The same for gravity.
void snap_roundoff_residues(Vec3& g_N);
/// v's entries at most kRoundoffResidue times `scale` set to 0: v a sum of terms of size up to `scale`.
void snap_roundoff_residues(Vec3& v, double scale);

/// Fills q/u layout, names, children, the offsets and names of the inputs
/// and sensors, and chain_u of an otherwise complete
/// model, and the mass integrals of every body. Called by the loader, and by
/// code that builds models programmatically (benchmarks, tests).
void finalize_model(Model& model);

}  // namespace kanegen
