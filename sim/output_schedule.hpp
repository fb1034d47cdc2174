// Output times of an integration: t0 < t0 + dt < ... < t_end.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace kanegen {

/// Output times t0 < t0 + dt < ... < t_end (t_end always last, no near-duplicate).
class OutputSchedule {
 public:
  OutputSchedule(double t0, double t_end, double dt) : t0_(t0), t_end_(t_end), dt_(dt) {
    tol_ = 1e-9 * dt + 16 * std::numeric_limits<double>::epsilon() * std::max(std::abs(t0), std::abs(t_end));
  }
  /// Next output time after the previous one; false when t_end was returned.
  bool next(double& t) {
    if (done_) return false;
    ++k_;
    double tk = t0_ + static_cast<double>(k_) * dt_;
    if (tk >= t_end_ - tol_) {
      tk = t_end_;
      done_ = true;
    }
    t = tk;
    return true;
  }

 private:
  double t0_, t_end_, dt_, tol_;
  long long k_ = 0;
  bool done_ = false;
};

}  // namespace kanegen
