// Explicit embedded Runge-Kutta methods of Boost.Odeint (dopri5, rkf78) for
// integrate() (integrators.hpp); see odeint_integrators.cpp.
#pragma once

#include "sim/integrators.hpp"

namespace kanegen {

IntegratorStats integrate_odeint(const OdeProblem& problem, const IntegratorOptions& options, double t0,
                                 const Eigen::VectorXd& x0, double t_end, double dt_out, const OutputFn& output,
                                 IntegratorStats stats, double grid_origin);

}  // namespace kanegen
