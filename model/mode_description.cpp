#include "model/mode_description.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>

namespace kanegen {

namespace {

constexpr const char* kAxis[3] = {"x", "y", "z"};

/// The B axis along which the nodes spread, if they spread along one line: the
/// largest principal spread at least 10 times (in length, 100 in second moment)
/// the next, and nearly parallel to a body axis.
int slender_axis(const FlexibleData& f) {
  double m = 0.0;
  Vec3 c = Vec3::Zero();
  for (const ModalNode& n : f.nodes) {
    m += n.mass;
    c += n.mass * n.rho_B;
  }
  if (m <= 0.0) return -1;
  c /= m;
  Mat3 C = Mat3::Zero();
  for (const ModalNode& n : f.nodes) C += n.mass * (n.rho_B - c) * (n.rho_B - c).transpose();
  const Eigen::SelfAdjointEigenSolver<Mat3> es(C);  // ascending
  const Vec3 l = es.eigenvalues();
  if (!(l(2) > 0.0) || l(1) > 1e-2 * l(2)) return -1;
  int a = 0;
  es.eigenvectors().col(2).cwiseAbs().maxCoeff(&a);
  return std::abs(es.eigenvectors()(a, 2)) > 0.99 ? a : -1;
}

std::string shape_of(const ModeDescription& d, int long_axis) {
  int at = 0, ar = 0;
  const double et = d.energy_translation.maxCoeff(&at), er = d.energy_rotation.maxCoeff(&ar);
  if (long_axis < 0)
    return er > et ? fmt::format("mostly rotation about {}", kAxis[ar]) : fmt::format("mostly {}-translation", kAxis[at]);
  if (er > et) {
    if (ar == long_axis) return fmt::format("torsion about {}", kAxis[ar]);
    return fmt::format("bending: node rotation about {}", kAxis[ar]);
  }
  if (at == long_axis) return fmt::format("axial along {}", kAxis[at]);
  const int about = 3 - at - long_axis;  // the third axis
  return fmt::format("bending: deflection along {} (about {})", kAxis[at], kAxis[about]);
}

}  // namespace

FlexibleBodyModes describe_modes(const Body& body) {
  const FlexibleData& f = *body.flex;
  FlexibleBodyModes out;
  out.long_axis = slender_axis(f);
  for (std::size_t k = 0; k < f.nodes.size(); ++k) {
    // a node no kept mode moves (a clamped root node) is no part of what the modes can carry
    if (f.Phi.middleRows(3 * k, 3).isZero(0.0) && f.Psi.middleRows(3 * k, 3).isZero(0.0)) continue;
    const ModalNode& n = f.nodes[k];
    out.node_mass += n.mass;
    const Vec3& r = n.rho_B;
    out.node_inertia_O += n.mass * Vec3(r.y() * r.y() + r.z() * r.z(), r.x() * r.x() + r.z() * r.z(),
                                        r.x() * r.x() + r.y() * r.y()) +
                          n.J_B.diagonal();
  }
  for (int j = 0; j < f.modes(); ++j) {
    ModeDescription d;
    Vec3 L_t = Vec3::Zero(), L_r = Vec3::Zero();
    for (std::size_t k = 0; k < f.nodes.size(); ++k) {
      const ModalNode& n = f.nodes[k];
      const Vec3 phi = f.Phi.block<3, 1>(3 * k, j), psi = f.Psi.block<3, 1>(3 * k, j);
      d.energy_translation += n.mass * phi.cwiseAbs2();
      d.energy_rotation += psi.cwiseProduct(n.J_B * psi);  // J psi's diagonal share (the sum is psi^T J psi)
      L_t += n.mass * phi;
      L_r += n.mass * n.rho_B.cross(phi) + n.J_B * psi;
    }
    const double Y = d.energy_translation.sum() + d.energy_rotation.sum();
    if (Y > 0.0) {
      d.energy_translation /= Y;
      d.energy_rotation /= Y;
      d.effective_mass = L_t.cwiseAbs2() / Y;
      d.effective_inertia = L_r.cwiseAbs2() / Y;
    }
    d.shape = shape_of(d, out.long_axis);
    out.modes.push_back(std::move(d));
  }
  return out;
}

}  // namespace kanegen
