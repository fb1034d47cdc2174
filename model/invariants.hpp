// Which invariants a scene keeps, decided from its physics and said with the
// reason when one is ruled out (docs/decisions.md, "Invariants"):
//  - energy T + V (springs and uniform gravity are in V) is kept unless
//    something does work on the system: joint dampers or modal damping
//    (dissipation), a prescribed motion (its driver), generalized inputs tau
//    or named inputs (constant non-zero ones, or any a controller sets);
//  - the momenta p and H about N's origin are kept by a free system: every
//    root joint free, no uniform gravity, and every applied force internal:
//    tau and joint torques on the speeds of a joint between two bodies (a
//    wheel's motor, a hinge's damper, a prescribed internal joint) act on
//    both, while a thruster, a force or torque on a body, or a torque on a
//    root joint's speeds come from outside.
// With prescribed motion the only thing doing work, the balance E - E(0) = W
// (the drivers' work) still holds, and is what the summary reports.
// Latches and locks act per segment (sim/simulate.cpp): a latch takes energy
// (it is reported, ev.energy_lost), a root joint locked to ground holds p and H.
#pragma once

#include <string>
#include <vector>

#include "model/model.hpp"

namespace kanegen {

struct Invariants {
  bool energy = true;    ///< T + V
  bool momentum = true;  ///< p and H about N's origin
  /// H about N's origin alone (central gravity without J2 turns p, not H; dynamics.md, "Invariants").
  bool angular_momentum = true;
  /// H_z alone, about N's z axis (central gravity with J2: the field is axisymmetric about N's z).
  bool angular_momentum_z = false;
  /// Energy is broken by prescribed motion alone: T + V minus the drivers' work is kept
  /// (sim/driver_work.hpp measures that balance).
  bool energy_with_drivers = false;
  std::vector<std::string> energy_broken_by, momentum_broken_by;  ///< why not, one phrase each
  /// "" when both hold; else "energy not conserved: dampers on 4 joints; p, H not conserved: gravity"
  std::string note() const;
};

/// `tau`: the generalized inputs of the run; `w`: its named inputs;
/// `controlled`: a controller sets the named inputs (any may be non-zero).
Invariants invariants_of(const Model& model, const VecX& tau, const VecX& w, bool controlled);

}  // namespace kanegen
