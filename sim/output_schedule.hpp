// Output times of an integration: t0, then the grid origin + k dt after t0, then t_end.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace kanegen {

/// Output times after t0: origin + k dt for every k with t0 < origin + k dt < t_end,
/// then t_end (always last, no near-duplicate of t0, a grid time or t_end). The
/// origin defaults to t0; a segment of a run that restarts at an event keeps
/// the run's grid.
class OutputSchedule {
 public:
  OutputSchedule(double t0, double t_end, double dt, double origin = std::numeric_limits<double>::quiet_NaN())
      : t0_(t0), t_end_(t_end), dt_(dt), origin_(std::isfinite(origin) ? origin : t0) {
    tol_ = 1e-9 * dt + 16 * std::numeric_limits<double>::epsilon() *
                           std::max({std::abs(t0), std::abs(t_end), std::abs(origin_)});
    k_ = static_cast<long long>(std::floor((t0 - origin_) / dt)) - 1;
  }
  /// Whether output time t comes before an event at t_event (not on it: the event's rows stand for it).
  bool before(double t, double t_event) const { return t < t_event - tol_; }
  /// Next output time after the previous one; false when t_end was returned.
  bool next(double& t) {
    if (done_) return false;
    double tk;
    do {
      ++k_;
      tk = origin_ + static_cast<double>(k_) * dt_;
    } while (tk <= t0_ + tol_);
    if (tk >= t_end_ - tol_) {
      tk = t_end_;
      done_ = true;
    }
    t = tk;
    return true;
  }

 private:
  double t0_, t_end_, dt_, origin_, tol_;
  long long k_ = 0;
  bool done_ = false;
};

}  // namespace kanegen
