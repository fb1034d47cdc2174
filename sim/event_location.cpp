#include "sim/event_location.hpp"

#include <boost/math/tools/toms748_solve.hpp>
#include <cmath>
#include <cstdint>

namespace kanegen {

namespace {
int sign_of(double g) { return g > 0 ? 1 : g < 0 ? -1 : 0; }
}  // namespace

EventLocator::EventLocator(const OdeProblem& problem)
    : problem_(problem), n_(problem.events ? problem.n_events : 0), g_ref_(n_), g_new_(n_), sign_ref_(n_) {}

void EventLocator::reset(double t, const double* x) {
  if (!n_) return;
  problem_.events(t, x, g_ref_.data());
  for (int i = 0; i < n_; ++i) {
    const int s = sign_of(g_ref_[i]);
    // a function that started on its surface takes its side when it leaves it
    if (s != 0 || sign_ref_[i] == 0) sign_ref_[i] = s;
  }
}

bool EventLocator::crossed(double t_b, const double* x_b) {
  crossed_.clear();
  if (!n_) return false;
  problem_.events(t_b, x_b, g_new_.data());
  for (int i = 0; i < n_; ++i)
    if (sign_ref_[i] != 0 && sign_of(g_new_[i]) != sign_ref_[i]) crossed_.push_back(i);
  return !crossed_.empty();
}

EventLocator::Root EventLocator::locate(double t_a, double t_b,
                                        const std::function<void(double t, double* x)>& state_at) {
  Root best;
  best.t = t_b;
  x_work_.resize(problem_.n);
  std::vector<double> g(n_);
  for (int i : crossed_) {
    double t_root = t_b;
    if (g_new_[i] != 0.0) {
      auto f = [&](double t) {
        state_at(t, x_work_.data());
        problem_.events(t, x_work_.data(), g.data());
        return g[i];
      };
      // the reference value is that at t_a: the sign it had there
      const double f_a = g_ref_[i] != 0.0 ? g_ref_[i] : f(t_a);
      std::uintmax_t iterations = 200;
      const auto bracket = boost::math::tools::toms748_solve(f, t_a, t_b, f_a, g_new_[i],
                                                             boost::math::tools::eps_tolerance<double>(52), iterations);
      // the end of the final bracket on the far side of the crossing
      t_root = sign_of(f(bracket.first)) != sign_ref_[i] ? bracket.first : bracket.second;
    }
    if (best.event < 0 || t_root < best.t) {
      best.t = t_root;
      best.event = i;
    }
  }
  best.x.resize(problem_.n);
  state_at(best.t, best.x.data());
  return best;
}

}  // namespace kanegen
