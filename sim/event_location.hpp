// Locating where an integration crosses an event surface g_i(t, x) = 0
// (OdeProblem::events): after every accepted step the integrators ask
// whether some g_i changed sign over the step and, if so, find the earliest
// crossing on the step's own interpolant (dense output, or one step of the
// same method from the step's start) by a bracketing solve (TOMS 748) to
// round-off in t. Every integrator family uses this one locator.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <vector>

#include "sim/integrators.hpp"
#include "sim/output_schedule.hpp"

namespace kanegen {

class EventLocator {
 public:
  explicit EventLocator(const OdeProblem& problem);
  bool active() const { return n_ > 0; }
  /// The reference signs at an accepted state (the start, or the end of a step without a crossing).
  void reset(double t, const double* x);
  /// After a step to (t_b, x_b): whether some g_i went from its reference sign to the other one or to zero.
  bool crossed(double t_b, const double* x_b);
  struct Root {
    double t = 0;
    int event = -1;     ///< index of the event function
    Eigen::VectorXd x;  ///< the state there (on the far side of the crossing, or on it)
  };
  /// The earliest crossing in (t_a, t_b] of the functions crossed() found,
  /// with `state_at(t, x)` the step's interpolant on [t_a, t_b].
  Root locate(double t_a, double t_b, const std::function<void(double t, double* x)>& state_at);

 private:
  const OdeProblem& problem_;
  int n_;
  std::vector<double> g_ref_, g_new_;
  std::vector<int> sign_ref_;
  std::vector<int> crossed_;
  Eigen::VectorXd x_work_;
};

/// The last outputs of a run an event stopped: the schedule's times before
/// the event at t_event (`emit_at(t)`: the state there from the step's
/// interpolant, emitted; false to stop), then the event's own state
/// (`emit_event()`). `tout`: the schedule's current time.
template <class EmitAt, class EmitEvent>
void emit_up_to_event(double t_event, OutputSchedule& schedule, double& tout, EmitAt emit_at, EmitEvent emit_event) {
  bool go_on = true;
  for (bool more = true; more && go_on && schedule.before(tout, t_event); more = schedule.next(tout))
    go_on = emit_at(tout);
  if (go_on) emit_event();
}

}  // namespace kanegen
