// The generator's choice of body frames. A body's frame is a convention, not
// physics: M, F, u_dot, energy and momentum do not depend on it (q and u are
// joint quantities). The generic engine keeps the frames of the model file;
// the generator re-chooses them where that makes the equations sparser, as
// Featherstone's and RobCoGen's link frames do:
//
//   - a rigid body on a revolute or prismatic joint gets a frame B' whose z
//     axis is its joint axis (same origin O_B), so that its motion subspace is
//     a single coordinate vector and its joint rotation Rz(q) has four
//     non-zero entries;
//   - B''s x axis lies along the common normal of its axis and its main
//     child's axis (Denavit-Hartenberg), so that the constant rotation to that
//     child is a rotation about x alone, Rx(alpha), once a constant offset
//     delta is added to the child's joint angle (Rx(alpha) Rz(q + delta));
//   - B''s origin slides along its joint axis (which leaves the joint's motion
//     unchanged) to the foot of that common normal: the offset from B' to its
//     main child's frame is then a along the common normal plus d along the
//     child's axis, (a, 0, d) in the child's joint axes (McMillan and Orin's
//     axial screws), so that moving an articulated inertia, a wrench or a
//     motion to the parent costs fewer products; a leaf's origin slides to
//     the foot of the perpendicular from its parent's origin, so that the
//     offset has no component along its axis ((a, 0, 0) from the parent of
//     a main child);
//   - a revolute child that is not its parent's main child (a tree's other
//     branches) gets the first of McMillan and Orin's two screws as a turn:
//     its joint frame is R_PJ = Rz(beta) Rx(alpha) (Rz(delta) joined to the
//     joint rotation as above), the parent's x axis turned by beta about the
//     parent's joint axis onto the common normal to the child's axis, so
//     that the constant turn between them is two turns about coordinate
//     axes (12 products and sums per vector, 30 or so per inertia) instead
//     of a dense matrix (15 per vector, 66 per inertia). The parent's origin
//     stays at its main child's foot, so the offset keeps three components.
//
// Only the generator's internal quantities change; reactions, reported in the
// model's body axes about the model's origin O_B, are turned back by the
// constant R_BB' and moved back by the constant o_B.
#pragma once

#include <vector>

#include "model/model.hpp"

namespace kanegen::codegen {

struct FramedModel {
  Model model;                       ///< same bodies, q and u; re-chosen body frames
  std::vector<Mat3> R_BBp;           ///< per body: axes of the new frame B' in the model's frame B
  std::vector<double> angle_offset;  ///< per body: revolute joint rotation Rz(q + offset) (0 otherwise)
  std::vector<Vec3> o_B;             ///< per body: the origin of B' from O_B, the model's body axes (along the axis)
  /// per body: R_PJ = Rz(screw_angle) Rx(alpha) for a revolute child other than its parent's main child
  /// (model.bodies[j].joint.R_PJ holds that product); 0 otherwise (R_PJ = Rx(alpha) or as the model has it)
  std::vector<double> screw_angle;
};

/// Rx(a), Rz(a): turns by a about x, about z.
Mat3 rot_x(double a);
Mat3 rot_z(double a);

/// The model with re-chosen body frames (see the header comment).
FramedModel choose_joint_frames(const Model& model);

/// The model unchanged, with identity frames and no offsets.
FramedModel keep_joint_frames(const Model& model);

}  // namespace kanegen::codegen
