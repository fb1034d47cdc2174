// The motion a lock defines (dynamics.md, "Locks"), from the M and F either
// engine computes: the reduced equations M_ff u_dot_f = F_f while joints are
// locked, and the perfectly plastic latch when a joint locks. Which speeds a
// lock set holds is model/events.hpp's locked_speeds().
#pragma once

#include <vector>

#include "model/model.hpp"

namespace kanegen {

/// u_dot of the reduced system: u_dot_f solves M_ff u_dot_f = F_f (F at
/// u_l = 0), u_dot_l = 0. `locked`: ascending speed indices. Throws
/// SingularMassMatrix (engine.hpp) when M_ff is not positive definite.
void reduced_udot(const MatX& M, const VecX& F, const std::vector<int>& locked, VecX& udot);

/// A lock event (a perfectly plastic latch) at one configuration: with M
/// there and the speeds u_minus just before, the speeds just after are
/// u_l+ = 0 and M_ff u_f+ = M_ff u_f- + M_fl u_l- (the free speeds'
/// generalized momentum conserved), and the kinetic energy lost
/// dT = 1/2 u-' M u- - 1/2 u+' M u+ >= 0, formed from the stopped speeds
/// alone: 1/2 u_l-' (M_ll - M_lf M_ff^-1 M_fl) u_l- (no difference of two
/// large kinetic energies: an orbit's T is 1e10 J). `locked_after`: every
/// speed locked after the event (those locked before included; their speeds are 0).
struct LatchImpact {
  VecX u_plus;
  double energy_lost = 0;
};
LatchImpact latch_impact(const MatX& M, const VecX& u_minus, const std::vector<int>& locked_after);

}  // namespace kanegen
