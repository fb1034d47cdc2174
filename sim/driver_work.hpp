// The energy balance of a scene whose only source of work is prescribed motion
// (model/invariants.hpp, energy_with_drivers): E(t) - E(0) = W(t), with W the
// work the drivers of the prescribed joints do. A driver's power is its
// joint's reaction along the joint axis (the torque about it for a revolute,
// the force along it for a prismatic joint: the only component the relative
// motion does work with) times the prescribed rate f_dot(t). W is the
// integral of that power over the run's kept output states, by the piecewise
// cubic through each interval's four nearest samples (fourth order in the
// spacing).
#pragma once

#include "engine/engine.hpp"
#include "sim/work_precision.hpp"

namespace kanegen {

/// The drivers' power at a state (W), on the engine's current inputs.
double driver_power(Engine& engine, double t, const VecX& q, const VecX& u, const VecX& tau);

struct EnergyBalance {
  double residual = NAN;    ///< max over the segment's states |E - E0 - W| / max(T + |V|)
  /// The share of it the quadrature of W on the samples can explain: |W_h - W_2h| / 15 (W on every
  /// other sample; the rule is fourth order), same scale. A residual near it says: refine --dt-out.
  double quadrature = NAN;
};

EnergyBalance energy_balance(Engine& engine, const bench::Trajectory& segment, const VecX& tau);

}  // namespace kanegen
