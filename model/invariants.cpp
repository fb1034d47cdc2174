#include "model/invariants.hpp"

#include <fmt/format.h>

#include "model/events.hpp"
#include "model/joints/joint_traits.hpp"

namespace kanegen {

namespace {

std::string count(std::size_t n, const char* one, const char* many) {
  return fmt::format("{} {}", n, n == 1 ? one : many);
}

std::string names(const std::vector<std::string>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size() && i < 4; ++i) s += (i ? ", " : "") + v[i];
  return v.size() > 4 ? s + ", ..." : s;
}

}  // namespace

std::string Invariants::note() const {
  std::string s;
  auto join = [](const std::vector<std::string>& v) {
    std::string j;
    for (const auto& x : v) j += (j.empty() ? "" : ", ") + x;
    return j;
  };
  if (!energy) s += "energy not conserved: " + join(energy_broken_by);
  if (!momentum)
    s += (s.empty() ? "" : "; ") + std::string(angular_momentum ? "p not conserved: " : "p, H not conserved: ") +
         join(momentum_broken_by);
  return s;
}

Invariants invariants_of(const Model& model, const VecX& tau, const VecX& w, bool controlled) {
  Invariants inv;
  std::vector<std::string> damped_joints, damped_bodies, prescribed, grounded, external_inputs, driven_inputs;
  for (const Body& b : model.bodies) {
    bool damped = false;
    for (const SpringSlot& sl : spring_slots(b.joint))
      if (b.joint.damping[sl.value] != 0) damped = true;
    if (damped) damped_joints.push_back(b.name);
    if (b.flex && b.flex->D.size() > 0 && !b.flex->D.isZero(0.0)) damped_bodies.push_back(b.name);
    if (b.joint.prescribed()) prescribed.push_back(b.name);
    if (b.parent < 0 && b.joint.type != JointType::free) grounded.push_back(b.name);
  }
  // generalized inputs: internal on a joint between two bodies
  std::vector<std::string> tau_external;
  bool tau_any = false;
  for (Eigen::Index k = 0; k < tau.size(); ++k) {
    if (tau(k) == 0.0) continue;
    tau_any = true;
    const int b = joint_body_of_speed(model, static_cast<int>(k));
    if (b >= 0 && model.bodies[b].parent < 0) tau_external.push_back(model.u_names[k]);
  }
  for (const Input& in : model.inputs) {
    bool active = controlled;
    for (int k = 0; k < in.size() && !active; ++k)
      if (in.offset + k < w.size() && w(in.offset + k) != 0.0) active = true;
    if (!active) continue;
    driven_inputs.push_back(in.name);
    const bool internal = in.type == InputType::joint_torque && in.body >= 0 && model.bodies[in.body].parent >= 0;
    if (!internal) external_inputs.push_back(in.name);
  }
  auto& e = inv.energy_broken_by;
  if (!damped_joints.empty()) e.push_back(fmt::format("dampers on {} ({})", count(damped_joints.size(), "joint", "joints"), names(damped_joints)));
  if (!damped_bodies.empty()) e.push_back(fmt::format("modal damping of {} ({})", count(damped_bodies.size(), "flexible body", "flexible bodies"), names(damped_bodies)));
  if (!prescribed.empty()) e.push_back(fmt::format("prescribed motion of {} (its driver does work)", names(prescribed)));
  if (tau_any) e.push_back("generalized inputs tau");
  if (!driven_inputs.empty())
    e.push_back(fmt::format("{} {} ({})", controlled ? "a controller setting" : "applied", count(driven_inputs.size(), "input", "inputs"), names(driven_inputs)));
  auto& m = inv.momentum_broken_by;
  if (!grounded.empty()) m.push_back(fmt::format("the root joint of {} is not free (the ground reacts)", names(grounded)));
  if (!model.g_N.isZero(0.0)) m.push_back("uniform gravity");
  if (model.central) m.push_back(model.central->J2 != 0.0 ? "central gravity with J2 (only H_z is kept)"
                                                          : "central gravity (H about N's origin is kept)");
  if (!tau_external.empty()) m.push_back(fmt::format("tau on a root joint's speeds ({})", names(tau_external)));
  if (!external_inputs.empty())
    m.push_back(fmt::format("external {} ({})", count(external_inputs.size(), "input", "inputs"), names(external_inputs)));
  inv.energy = e.empty();
  inv.energy_with_drivers = e.size() == 1 && !prescribed.empty();
  inv.momentum = m.empty();
  // central gravity without J2 is the only thing changing the momenta: H about N's origin holds
  inv.angular_momentum = inv.momentum || (m.size() == 1 && model.central && model.central->J2 == 0.0);
  // with J2 (axisymmetric about N's z) the only thing changing them: H_z about N's z axis holds
  inv.angular_momentum_z = !inv.angular_momentum && m.size() == 1 && model.central && model.central->J2 != 0.0;
  return inv;
}

}  // namespace kanegen
