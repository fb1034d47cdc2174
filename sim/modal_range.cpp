#include "sim/modal_range.hpp"

#include <fmt/format.h>

namespace kanegen {

ModalRange::ModalRange(const Model& model) : model_(model) {
  for (int b = 0; b < static_cast<int>(model.bodies.size()); ++b) {
    const auto& flex = model.bodies[b].flex;
    if (!flex || flex->modes() == 0) continue;
    ModalExcursion e;
    e.body = b;
    for (const ModalNode& n : flex->nodes) e.extent_m = std::max(e.extent_m, n.rho_B.norm());
    excursions_.push_back(e);
  }
}

void ModalRange::add(double t, const VecX& q) {
  for (ModalExcursion& e : excursions_) {
    const Body& b = model_.bodies[e.body];
    const FlexibleData& f = *b.flex;
    const VecX d = f.Phi * q.segment(b.q_eta, f.modes());
    for (int k = 0; k < static_cast<int>(f.nodes.size()); ++k) {
      const double dk = d.segment<3>(3 * k).norm();
      if (dk > e.deflection_m) {
        e.deflection_m = dk;
        e.node_id = f.nodes[k].id;
        e.t = t;
      }
    }
  }
}

std::vector<std::string> ModalRange::warnings(double fraction) const {
  std::vector<std::string> w;
  for (const ModalExcursion& e : excursions_)
    if (e.extent_m > 0 && e.deflection_m > fraction * e.extent_m)
      w.push_back(fmt::format("{}'s modal deflection reached {:.3g} m at node {} (t = {:.6g} s): {:.0f} % of its "
                              "{:.3g} m extent, beyond the small deflections modal flexibility describes "
                              "(above {:.0f} %)",
                              model_.bodies[e.body].name, e.deflection_m, e.node_id, e.t,
                              100 * e.deflection_m / e.extent_m, e.extent_m, 100 * fraction));
  return w;
}

}  // namespace kanegen
