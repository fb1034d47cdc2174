// Per-body inertia and gravity terms for the current kinematics.
#pragma once

#include "dynamics/body_inertia.hpp"
#include "model/model.hpp"
#include "dynamics/workspace.hpp"

namespace kanegen {

template <class S>
void compute_body_terms(const Model& model, Workspace<S>& ws) {
  const V3<S> g_N = model.g_N.cast<S>();
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    BodyWorkspace<S>& s = ws.body[i];
    const V3<S> g_B = s.R_NB.transpose() * g_N;
    compute_body_inertia<S>(model.bodies[i].integrals, s.eta, s.eta_dot, s.w_B, g_B, s.M_body, s.h_body, s.g_body,
                            s.Q);
  }
}

}  // namespace kanegen
