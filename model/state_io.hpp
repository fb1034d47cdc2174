// STATE.json (interface.md) and initial states.
#pragma once

#include <string>

#include "model/diagnostics.hpp"
#include "model/model.hpp"

namespace kanegen {

struct State {
  double t = 0.0;
  VecX q;    ///< nq, quaternions normalized
  VecX u;    ///< nu
  VecX tau;  ///< nu generalized inputs
  VecX w;    ///< nw named inputs (docs/gnc.md), by name under "inputs"
  int q_line = 0;  ///< line of "q" in the STATE.json it was read from (0: q from the model)
  /// Per body: its joint locked (model/events.hpp); the model's `locked: true`
  /// joints unless a STATE.json lists them under "locked".
  LockSet locked;
};

/// The model's `initial:` state, zero inputs.
State initial_state(const Model& model);

/// Reads STATE.json: names not given take the model's initial value (else 0);
/// a quaternion given in part is refused; quaternions of any non-zero norm are
/// normalized. Unknown names, wrong types, zero quaternions, a missing file or
/// malformed JSON throw InputError naming the file and the field (e.g. "q.foo").
State load_state(const Model& model, const std::string& path);

}  // namespace kanegen
