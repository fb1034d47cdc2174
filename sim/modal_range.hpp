// How far a run took each flexible body's modal deflection, against the body's
// size. Modal flexibility (dynamics.md, "Flexible bodies") is a small-deflection
// model: node k at rho_k + Phi_k eta (+ foreshortening); a tip that swings by a
// sizeable fraction of the body's length is outside what it describes, and a
// run that goes there says so (docs/decisions.md, "Modal deflection beyond the
// linear range").
#pragma once

#include <string>
#include <vector>

#include "model/model.hpp"

namespace kanegen {

/// A run's deflection warnings flag a node's |Phi_k eta| above this fraction of the body's extent.
inline constexpr double kLinearRangeFraction = 0.1;

/// The largest linear deflection |Phi_k eta| of one flexible body over the states it was shown.
struct ModalExcursion {
  int body = -1;
  double extent_m = 0;     ///< the body's extent: the largest |rho_k| of its nodes from O
  double deflection_m = 0;  ///< the largest |Phi_k eta| seen
  int node_id = 0;          ///< at this node (its id in the modal data)
  double t = 0;             ///< at this time
};

class ModalRange {
 public:
  explicit ModalRange(const Model& model);
  /// A state of the run (q as the engines take it).
  void add(double t, const VecX& q);
  const std::vector<ModalExcursion>& excursions() const { return excursions_; }
  /// One line per flexible body whose deflection exceeded `fraction` of its extent.
  std::vector<std::string> warnings(double fraction = kLinearRangeFraction) const;

 private:
  const Model& model_;
  std::vector<ModalExcursion> excursions_;
};

}  // namespace kanegen
