// A control law in the loop of a simulation (docs/gnc.md): a function from
// the time, the state and the named outputs (sensors) to the named inputs w.
//   - continuous (period 0): called inside the right-hand side, at every
//     evaluation, with the outputs at that state; it must be a pure function
//     of its arguments (the integrator evaluates trial states it may reject);
//   - digital (period > 0): called every `period` seconds from the start, as
//     flight software runs: the outputs are sampled at the sample time (with
//     the inputs held until then), the new inputs are held constant until the
//     next sample (zero-order hold) and the integrator restarts at each
//     sample. State of the controller's own (integrators, filters, a mode)
//     is safe here: each sample is called once, in order.
// In both modes the outputs a law sees are computed with the inputs then
// applied (an accelerometer's reading depends on them: no algebraic loop).
#pragma once

#include <functional>

#include "model/model.hpp"

namespace kanegen {

struct Controller {
  /// (t, q, u, y) -> w: `w` holds the inputs applied so far on entry (nw values).
  std::function<void(double t, const VecX& q, const VecX& u, const VecX& y, VecX& w)> law;
  double period = 0.0;  ///< seconds between samples; 0: continuous
  explicit operator bool() const { return static_cast<bool>(law); }
};

}  // namespace kanegen
