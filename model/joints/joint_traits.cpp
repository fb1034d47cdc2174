#include "model/joints/joint_traits.hpp"

#include <cmath>
#include <stdexcept>

#include "model/joints/joint_kinematics.hpp"
#include "model/joints/joint_types.hpp"

namespace kanegen {

const std::vector<const JointTraits*>& all_joint_traits() {
  // The registry: one line per joint type, in JointType order.
  static const std::vector<const JointTraits*> all = {
      &revolute_traits(),  &prismatic_traits(), &fixed_traits(),  &free_traits(), &universal_traits(),
      &gimbal_traits(),    &cylindrical_traits(), &planar_traits(), &ball_traits()};
  return all;
}

const JointTraits& joint_traits(JointType t) {
  const auto& all = all_joint_traits();
  const auto i = static_cast<std::size_t>(t);
  if (i >= all.size() || all[i]->type != t) throw std::logic_error("joint_traits: registry out of order");
  return *all[i];
}

const JointTraits* joint_traits_named(const std::string& name) {
  for (const JointTraits* t : all_joint_traits())
    if (t->name == name) return t;
  return nullptr;
}

std::vector<std::string> JointTraits::keys() const {
  std::vector<std::string> k = {"type", "position", "node", "rotation"};
  if (axes == Axes::one) k.push_back("axis");
  if (axes == Axes::list) k.push_back("axes");
  if (sequence) k.push_back("sequence");
  if (springs > 0) k.insert(k.end(), {"stiffness", "damping", "rest"});
  if (damping_only) k.push_back("damping");
  if (prescribable) k.push_back("motion");
  return k;
}

bool speed_is_angular(const JointTraits& t, int i) {
  if (t.angular_speeds >= 0 && i >= t.angular_speeds && i < t.angular_speeds + 3) return true;
  return i < static_cast<int>(t.units.size()) && t.units[i] == "rad";
}

SpringSlots spring_slots(const Joint& j) {
  SpringSlots s;
  if (j.prescribed()) return s;
  const JointTraits& t = joint_traits(j.type);
  for (int i = 0; i < t.springs; ++i) s.slot[s.n++] = {i, i, i};
  if (t.damping_only)
    for (int k = 0; k < 3; ++k) s.slot[s.n++] = {0, -1, t.angular_speeds + k};
  return s;
}

double joint_lock_measure(const Joint& j, const double* q) { return std::abs(joint_lock_determinant(j, q)); }

double joint_lock_determinant(const Joint& j, const double* q) {
  const JointTraits& t = joint_traits(j.type);
  if (!t.can_lock_up) return 1.0;
  const auto prims = t.primitives(j);
  std::vector<joints::Vec<double>> axes;
  for (const auto& p : prims) axes.push_back({p.axis(0), p.axis(1), p.axis(2)});
  const auto jm = joints::joint_motion<double>(prims, axes, t.nu(), q, nullptr, false, [](double x) { return x; });
  const auto& a = jm.Sw[0];
  const auto& b = jm.Sw[1];
  const auto& c = jm.Sw[2];
  return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
         a[2] * (b[0] * c[1] - b[1] * c[0]);
}

}  // namespace kanegen
