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
//     delta is added to the child's joint angle (Rx(alpha) Rz(q + delta)).
//
// Only the generator's internal quantities change; reactions, reported in the
// model's body axes, are rotated back by the constant R_BB'.
#pragma once

#include <vector>

#include "model/model.hpp"

namespace kanegen::codegen {

struct FramedModel {
  Model model;                       ///< same bodies, q and u; re-chosen body frames
  std::vector<Mat3> R_BBp;           ///< per body: axes of the new frame B' in the model's frame B
  std::vector<double> angle_offset;  ///< per body: revolute joint rotation Rz(q + offset) (0 otherwise)
};

/// The model with re-chosen body frames (see the header comment).
FramedModel choose_joint_frames(const Model& model);

/// The model unchanged, with identity frames and no offsets.
FramedModel keep_joint_frames(const Model& model);

}  // namespace kanegen::codegen
