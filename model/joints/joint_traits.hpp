// What a joint type is, asked in one place: its coordinates and speeds and
// their names, where its quaternion sits, which coordinates take springs and
// dampers, which keys its model entry takes, its configuration operations and
// its kinematics as a list of primitives (joint_primitive.hpp, evaluated by
// joint_kinematics.hpp for numbers and symbols). Each type is one file of this
// folder (revolute.cpp, ..., ball.cpp) and one line of joint_traits.cpp.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "model/joints/joint.hpp"
#include "model/joints/joint_primitive.hpp"

namespace kanegen {

struct JointTraits {
  JointType type = JointType::fixed;
  std::string name;                       ///< as in the model file
  std::vector<std::string> coordinates;   ///< q name suffixes: "<body>.<suffix>"
  std::vector<std::string> speeds;        ///< u name suffixes; a coordinate's rate is "<coordinate>_rate"
  std::vector<std::string> units;         ///< per coordinate: "rad", "m" or "" (quaternion)
  int quaternion = -1;                    ///< q offset of the unit quaternion [w x y z], -1 if none
  int angular_speeds = -1;                ///< u offset of its angular velocity (B components)
  int springs = 0;                        ///< coordinates 0..springs-1 take stiffness, damping, rest (q_i <-> u_i)
  bool damping_only = false;              ///< ball: one damping on its angular speeds, no spring
  /// Axis keys: none, `axis:` (one unit vector), or `axes:` (n_axes unit vectors).
  enum class Axes { none, one, list } axes = Axes::none;
  int n_axes = 0;
  std::vector<Vec3> default_axes;         ///< when `axes:` is not given
  bool sequence = false;                  ///< `sequence: xyz` accepted instead of axes (gimbal)
  bool prescribable = false;              ///< `motion:` allowed (revolute, prismatic)
  /// The joint's motions from J to B, in order.
  std::vector<JointPrimitive> (*primitives)(const Joint&) = nullptr;
  /// Gimbal lock: |det Gamma| of the rotation columns at coordinates q (the
  /// joint's own), for types that can lose a rank; null otherwise.
  bool can_lock_up = false;

  int nq() const { return static_cast<int>(coordinates.size()); }
  int nu() const { return static_cast<int>(speeds.size()); }
  bool has_quaternion() const { return quaternion >= 0; }
  /// The model-file keys of a joint entry this type takes.
  std::vector<std::string> keys() const;
};

/// The traits of a type (every JointType has them).
const JointTraits& joint_traits(JointType t);
/// The type named `name` in a model file, or nullptr.
const JointTraits* joint_traits_named(const std::string& name);
/// Every type, in enum order (for messages: "expected one of ...").
const std::vector<const JointTraits*>& all_joint_traits();

/// One spring-damper term of a joint (dynamics.md, Forces): generalized
/// force -k (q - rest) - c u on the joint's speed `u`, with k, c, rest the
/// joint's entries `value`; `q` is -1 for a damper alone (a ball's three
/// angular speeds share damping[0]). Offsets within the joint's q and u.
struct SpringSlot {
  int value = 0;
  int q = 0;
  int u = 0;
};
/// At most three terms, held without allocation (the engines ask per evaluation).
struct SpringSlots {
  std::array<SpringSlot, 3> slot{};
  int n = 0;
  const SpringSlot* begin() const { return slot.data(); }
  const SpringSlot* end() const { return slot.data() + n; }
};
/// The joint's spring-damper terms (none for a prescribed joint).
SpringSlots spring_slots(const Joint& j);

/// Kind of the joint's speed i: an angular rate (rad/s) or not (m/s).
bool speed_is_angular(const JointTraits& t, int i);

/// A random configuration of the joint (crosscheck, tests): angles uniform in
/// [-pi, pi], displacements in [-1, 1] m, quaternions uniform on the sphere.
/// `uniform` draws from [-1, 1], `normal` from N(0, 1). q: the joint's own.
template <class Uniform, class Normal>
void random_coordinates(const Joint& j, Uniform&& uniform, Normal&& normal, double* q) {
  const JointTraits& t = joint_traits(j.type);
  for (int i = 0; i < t.nq(); ++i) {
    if (t.has_quaternion() && i == t.quaternion) {
      double n = 0;
      for (int k = 0; k < 4; ++k) q[i + k] = normal(), n += q[i + k] * q[i + k];
      for (int k = 0; k < 4; ++k) q[i + k] /= std::sqrt(n);
      i += 3;
    } else {
      q[i] = (t.units[i] == "rad" ? 3.141592653589793 : 1.0) * uniform();
    }
  }
}

/// Gimbal lock measure |det Gamma(q)| (unit axes) of a joint whose traits can
/// lock up; 1 for every other joint. q: the joint's own coordinates.
double joint_lock_measure(const Joint& j, const double* q);
/// det Gamma(q) with its sign (it changes sign where a motion passes through
/// gimbal lock); 1 for a joint that cannot lock up.
double joint_lock_determinant(const Joint& j, const double* q);
/// Below these the joint is in gimbal lock: a state is refused (eval, check)
/// or a run stops (simulate) (dynamics.md).
inline constexpr double kGimbalLockRefuse = 1e-9;
inline constexpr double kGimbalLockStop = 1e-6;

}  // namespace kanegen
