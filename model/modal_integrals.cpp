#include "model/modal_integrals.hpp"

#include "model/model.hpp"

namespace kanegen {

static Eigen::Matrix3d point_inertia(double m, const Eigen::Vector3d& r) {
  return m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
}

BodyMassIntegrals compute_mass_integrals(const RigidPart& rigid, const FlexibleData* flex) {
  BodyMassIntegrals I;
  I.m = flex ? flex->modes() : 0;
  const int m = I.m;
  I.mass = rigid.mass;
  I.S0 = rigid.mass * rigid.com_B;
  I.J0 = rigid.I_c_B + point_inertia(rigid.mass, rigid.com_B);
  I.B = Eigen::MatrixXd::Zero(3, m);
  I.Y = Eigen::MatrixXd::Zero(m, m);
  for (auto& row : I.Prf)
    for (auto& v : row) v = Eigen::VectorXd::Zero(m);
  for (auto& row : I.Pff)
    for (auto& M : row) M = Eigen::MatrixXd::Zero(m, m);
  if (!flex) return I;
  for (std::size_t k = 0; k < flex->nodes.size(); ++k) {
    if (flex->node_is_rich(static_cast<int>(k))) continue;  // handled node by node (body_inertia.hpp)
    const ModalNode& node = flex->nodes[k];
    const double mk = node.mass;
    const Eigen::MatrixXd Phi_k = flex->Phi.middleRows(3 * k, 3);  // 3 x m
    I.mass += mk;
    I.S0 += mk * node.rho_B;
    I.J0 += point_inertia(mk, node.rho_B);  // a plain node has no rotary inertia
    I.B += mk * Phi_k;
    I.Y += mk * Phi_k.transpose() * Phi_k;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        I.Prf[a][b] += mk * node.rho_B(a) * Phi_k.row(b).transpose();
        I.Pff[a][b] += mk * Phi_k.row(a).transpose() * Phi_k.row(b);
      }
  }
  return I;
}

}  // namespace kanegen
