// The closed-form librations of a rigid body pointing LVLH on a circular orbit
// (the tests of runs and of linearize --frame lvlh compare with them).
#pragma once

#include <cmath>

namespace kanegen::test {

/// Principal axes along L's (x roll, y pitch, z yaw), orbit rate n: the pitch libration n sqrt(3 (Ix - Iz)/Iy)
/// and the roll-yaw pair at the roots of Hughes' characteristic equation
/// s^4 + (1 + 3 kR + kR kY) n^2 s^2 + 4 kR kY n^4 = 0 (Spacecraft Attitude Dynamics, ch. 9).
struct Librations {
  double pitch, roll_yaw_slow, roll_yaw_fast;
};
inline Librations rigid_librations(double Ix, double Iy, double Iz, double n) {
  const double kR = (Iy - Iz) / Ix, kY = (Iy - Ix) / Iz;
  const double B = 1.0 + 3.0 * kR + kR * kY, C = 4.0 * kR * kY;
  const double disc = std::sqrt(B * B - 4.0 * C);
  return {n * std::sqrt(3.0 * (Ix - Iz) / Iy), n * std::sqrt((B - disc) / 2.0), n * std::sqrt((B + disc) / 2.0)};
}

}  // namespace kanegen::test
