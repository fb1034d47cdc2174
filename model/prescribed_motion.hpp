// Prescribed motion of a revolute or prismatic joint (dynamics.md,
// model-format.md `motion:`): the joint coordinate f(t) with its rate and
// acceleration, a known function of time.
#pragma once

#include <string>
#include <vector>

namespace kanegen {

enum class MotionKind { polynomial, sine, spinup };

const char* to_string(MotionKind k);

struct MotionValue {
  double f = 0.0, f_dot = 0.0, f_ddot = 0.0;
};

struct PrescribedMotion {
  MotionKind kind = MotionKind::polynomial;
  std::vector<double> coefficients;  ///< polynomial: f = Sum c_i t^i (1 to 8 coefficients)
  double offset = 0.0;               ///< sine: f = offset + amplitude sin(2 pi frequency t + phase)
  double amplitude = 0.0;
  double frequency_hz = 0.0;
  double phase = 0.0;
  double rate = 0.0;                 ///< spinup (Kane, Ryan & Banerjee 1987): final rate Omega
  double duration = 0.0;             ///< its duration T (> 0)
  double start = 0.0;                ///< f at t <= 0

  MotionValue at(double t) const;
};

}  // namespace kanegen
