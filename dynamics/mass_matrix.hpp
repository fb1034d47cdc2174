// M(q) = Sum_j P_j^T M_body_j P_j (Kane: M_rs = Sum m v_r.v_s + w_r.I w_s),
// accumulated over each body's chain columns only, so entries between
// different kinematic chains stay exactly zero. Requires compute_kinematics
// and compute_body_terms.
#pragma once

#include "model/model.hpp"
#include "dynamics/workspace.hpp"

namespace kanegen {

template <class S>
void compute_mass_matrix(const Model& model, Workspace<S>& ws) {
  ws.M.setZero();
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const std::vector<int>& chain = model.bodies[i].chain_u;
    BodyWorkspace<S>& s = ws.body[i];
    s.MP.noalias() = s.M_body * s.P;
    const int k = static_cast<int>(chain.size());
    for (int c = 0; c < k; ++c)
      for (int r = c; r < k; ++r) ws.M(chain[r], chain[c]) += s.P.col(r).dot(s.MP.col(c));
  }
  for (int c = 0; c < model.nu; ++c)
    for (int r = c + 1; r < model.nu; ++r) ws.M(c, r) = ws.M(r, c);
}

}  // namespace kanegen
