#include "model/model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kanegen {

const char* to_string(JointType t) { return joint_traits(t).name.c_str(); }

int joint_nq(const Joint& j) { return j.prescribed() ? 0 : joint_traits(j.type).nq(); }
int joint_nu(const Joint& j) { return j.prescribed() ? 0 : joint_traits(j.type).nu(); }

int FlexibleData::node_index(int id) const {
  for (std::size_t k = 0; k < nodes.size(); ++k)
    if (nodes[k].id == id) return static_cast<int>(k);
  return -1;
}

static int find(const std::vector<std::string>& names, const std::string& name) {
  auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

int Model::body_index(const std::string& n) const {
  for (std::size_t i = 0; i < bodies.size(); ++i)
    if (bodies[i].name == n) return static_cast<int>(i);
  return -1;
}
int Model::q_index(const std::string& n) const { return find(q_names, n); }
int Model::u_index(const std::string& n) const { return find(u_names, n); }
int Model::speed_index(const std::string& n) const {
  const int k = find(u_names, n);
  return k >= 0 || n.empty() ? k : find(legacy_u_names, n);
}
int Model::input_index(const std::string& n) const { return find(input_names, n); }
int Model::output_index(const std::string& n) const { return find(output_names, n); }
bool Model::has_flexible() const {
  return std::any_of(bodies.begin(), bodies.end(), [](const Body& b) { return b.flex.has_value(); });
}

namespace {

void snap_unit(double& x) {
  for (double exact : {0.0, 1.0, -1.0})
    if (std::abs(x - exact) <= kRoundoffResidue) x = exact;
}

template <class M>
void snap_relative(M& m, double scale) {
  for (Eigen::Index i = 0; i < m.size(); ++i)
    if (std::abs(m(i)) <= kRoundoffResidue * scale) m(i) = 0.0;
}

}  // namespace

void snap_roundoff_residues(Vec3& v) { snap_relative(v, v.cwiseAbs().maxCoeff()); }

void snap_roundoff_residues(Vec3& v, double scale) { snap_relative(v, scale); }

void snap_unit_residues(Mat3& R) {
  for (Eigen::Index i = 0; i < 9; ++i) snap_unit(R(i));
}

void snap_roundoff_residues(Body& b) {
  snap_unit_residues(b.joint.R_PJ);
  for (Eigen::Index i = 0; i < 3; ++i) snap_unit(b.joint.axis_J(i));
  snap_roundoff_residues(b.joint.p_PJ);
  snap_roundoff_residues(b.rigid.com_B);
  snap_relative(b.rigid.I_c_B, b.rigid.I_c_B.diagonal().cwiseAbs().maxCoeff());
}

void finalize_model(Model& model) {
  model.q_names.clear();
  model.u_names.clear();
  model.prescribed_names.clear();
  model.quaternions.clear();
  model.lockable_joints.clear();
  int nq = 0, nu = 0;
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    Body& b = model.bodies[i];
    if (b.parent >= static_cast<int>(i)) throw std::logic_error("finalize_model: bodies not listed parents-first");
    b.children.clear();
    b.q_joint = nq;
    b.u_joint = nu;
    const std::string& n = b.name;
    const JointTraits& jt = joint_traits(b.joint.type);
    b.primitives = jt.primitives(b.joint);
    if (b.joint.prescribed()) {
      model.prescribed_names.push_back(n + "." + jt.coordinates[0]);
    } else {
      for (const auto& c : jt.coordinates) model.q_names.push_back(n + "." + c);
      for (const auto& c : jt.speeds) model.u_names.push_back(n + "." + c);
      if (jt.has_quaternion())
        model.quaternions.push_back({static_cast<int>(i), nq + jt.quaternion, nu + jt.angular_speeds});
      if (jt.can_lock_up) model.lockable_joints.push_back(static_cast<int>(i));
    }
    nq += joint_nq(b.joint);
    nu += joint_nu(b.joint);
    b.q_eta = nq;
    b.u_eta = nu;
    for (int k = 1; k <= b.n_modes(); ++k) {
      model.q_names.push_back(n + ".eta" + std::to_string(k));
      model.u_names.push_back(n + ".eta" + std::to_string(k) + "_rate");
    }
    nq += b.n_modes();
    nu += b.n_modes();
  }
  model.nq = nq;
  model.nu = nu;
  model.legacy_u_names.clear();
  for (const std::string& n : model.u_names) {
    const std::string suffix = "_rate";
    const bool rate = n.size() > suffix.size() && n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0;
    model.legacy_u_names.push_back(rate ? n.substr(0, n.size() - suffix.size()) : std::string());
  }
  model.input_names.clear();
  model.nw = 0;
  for (Input& in : model.inputs) {
    in.offset = model.nw;
    model.nw += in.size();
    for (auto& n : entry_names(in)) model.input_names.push_back(n);
  }
  model.output_names.clear();
  model.ny = 0;
  for (Sensor& s : model.sensors) {
    s.offset = model.ny;
    model.ny += s.size();
    for (auto& n : entry_names(s)) model.output_names.push_back(n);
  }
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    Body& b = model.bodies[i];
    if (b.parent >= 0) model.bodies[b.parent].children.push_back(static_cast<int>(i));
    std::vector<int> chain = b.parent >= 0 ? model.bodies[b.parent].chain_u : std::vector<int>{};
    for (int k = 0; k < joint_nu(b.joint) + b.n_modes(); ++k) chain.push_back(b.u_joint + k);
    std::sort(chain.begin(), chain.end());
    b.chain_u = std::move(chain);
    b.integrals = compute_mass_integrals(b.rigid, b.flex ? &*b.flex : nullptr);
    b.rich_nodes.clear();
    b.total_mass = b.rigid.mass;
    if (b.flex)
      for (int k = 0; k < static_cast<int>(b.flex->nodes.size()); ++k) {
        if (b.flex->node_is_rich(k)) b.rich_nodes.push_back(k);
        b.total_mass += b.flex->nodes[k].mass;
      }
  }
  if (model.q0.size() != nq) {
    model.q0 = VecX::Zero(nq);
    for (const auto& slot : model.quaternions) model.q0(slot.q) = 1.0;
  }
  if (model.u0.size() != nu) model.u0 = VecX::Zero(nu);
}

}  // namespace kanegen
