// Per-body inertia and gravity terms for the current kinematics.
#pragma once

#include "dynamics/body_inertia.hpp"
#include "dynamics/central_gravity.hpp"
#include "model/model.hpp"
#include "dynamics/workspace.hpp"

namespace kanegen {

template <class S>
void compute_body_terms(const Model& model, Workspace<S>& ws) {
  const V3<S> g_N = model.g_N.cast<S>();
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    BodyWorkspace<S>& s = ws.body[i];
    const V3<S> g_B = s.R_NB.transpose() * g_N;
    const Body& b = model.bodies[i];
    compute_body_inertia<S>(b.integrals, s.eta, s.eta_dot, s.w_B, g_B, s.M_body, s.h_body, s.g_body, s.Q);
    s.S_B = integrated_first_moment<S>(b.integrals, s.eta);
    for (int k : b.rich_nodes)
      add_node_terms<S>(*b.flex, k, s.eta, s.eta_dot, s.w_B, g_B, s.M_body, s.h_body, s.g_body, s.S_B, s.node_Phi,
                        s.node_H, s.node_JH, s.node_m);
  }
  if (model.central) add_central_gravity(model, ws);
}

}  // namespace kanegen
