#include "model/prescribed_motion.hpp"

#include <cmath>

namespace kanegen {

const char* to_string(MotionKind k) {
  switch (k) {
    case MotionKind::polynomial: return "polynomial";
    case MotionKind::sine: return "sine";
    case MotionKind::spinup: return "spinup";
  }
  return "?";
}

MotionValue PrescribedMotion::at(double t) const {
  constexpr double kTwoPi = 6.283185307179586476925;
  MotionValue v;
  switch (kind) {
    case MotionKind::polynomial: {
      // Horner for f and its two derivatives.
      for (std::size_t i = coefficients.size(); i-- > 0;) {
        v.f_ddot = v.f_ddot * t + 2.0 * v.f_dot;
        v.f_dot = v.f_dot * t + v.f;
        v.f = v.f * t + coefficients[i];
      }
      break;
    }
    case MotionKind::sine: {
      const double w = kTwoPi * frequency_hz, arg = w * t + phase;
      v.f = offset + amplitude * std::sin(arg);
      v.f_dot = amplitude * w * std::cos(arg);
      v.f_ddot = -amplitude * w * w * std::sin(arg);
      break;
    }
    case MotionKind::spinup: {
      const double T = duration, W = rate;
      if (t < 0.0) {
        v.f = start;
      } else if (t < T) {
        const double a = kTwoPi * t / T;
        v.f = start + W * (t * t / (2.0 * T) + (T / (kTwoPi * kTwoPi)) * (std::cos(a) - 1.0));
        v.f_dot = (W / T) * (t - (T / kTwoPi) * std::sin(a));
        v.f_ddot = (W / T) * (1.0 - std::cos(a));
      } else {
        v.f = start + W * (t - T / 2.0);
        v.f_dot = W;
      }
      break;
    }
  }
  return v;
}

}  // namespace kanegen
