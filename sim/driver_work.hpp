// The energy balance of a scene whose only source of work is prescribed motion
// (model/invariants.hpp, energy_with_drivers): E(t) - E(0) = W(t), with W the
// work the drivers of the prescribed joints do (dynamics.md, "Invariants"). A
// driver's power is its joint's reaction along the joint axis (the torque
// about it for a revolute, the force along it for a prismatic joint: the only
// component the relative motion does work with) times the prescribed rate
// f_dot(t). W is the integral of that power over every output row of the run,
// by the piecewise cubic through each interval's four nearest rows (fourth
// order in the output step).
#pragma once

#include <vector>

#include "engine/engine.hpp"

namespace kanegen {

/// The drivers' power at a state (W), on the engine's current inputs and locks.
double driver_power(Engine& engine, double t, const VecX& q, const VecX& u, const VecX& tau);

struct EnergyBalance {
  double residual = NAN;    ///< max over the rows |E - E0 - W| / max(T + |V|)
  /// The share of it the quadrature of W can explain: |W_h - W_2h| / 15 (W on every other row; the rule is
  /// fourth order), same scale; NaN with fewer than 5 rows. A residual near it says: refine --dt-out.
  double quadrature = NAN;
};

/// E and P at every output row of a run, segment by segment (a latch starts a new one).
class DriverWorkMeter {
 public:
  /// `engine` evaluates E and P (the generic engine: it has reactions at any state); kept by reference.
  DriverWorkMeter(Engine& engine, VecX tau) : engine_(engine), tau_(std::move(tau)) {}
  void new_segment(const LockSet& locks);
  void add(double t, const VecX& q, const VecX& u);
  /// The worst balance over the segments (NaN where a segment has fewer than 2 rows).
  EnergyBalance balance() const;

 private:
  struct Segment {
    std::vector<double> t, E, P;
    double scale = 0.0;
  };
  Engine& engine_;
  VecX tau_;
  std::vector<Segment> segments_{1};
};

/// The balance of one segment's rows (t ascending, distinct).
EnergyBalance energy_balance(const std::vector<double>& t, const std::vector<double>& E,
                             const std::vector<double>& P, double scale);

}  // namespace kanegen
