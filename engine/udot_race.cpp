#include "engine/udot_race.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

namespace kanegen {

namespace {

using Clock = std::chrono::steady_clock;

/// Calls per slice of about `slice_us`, from one timed call (at least 1).
long calls_per_slice(const std::function<void()>& call, double slice_us) {
  call();  // warm the caches
  const auto t0 = Clock::now();
  call();
  const double ns = std::max(1.0, std::chrono::duration<double, std::nano>(Clock::now() - t0).count());
  return std::max(1L, static_cast<long>(slice_us * 1e3 / ns));
}

double slice_ns(const std::function<void()>& call, long n) {
  const auto t0 = Clock::now();
  for (long i = 0; i < n; ++i) call();
  return std::chrono::duration<double, std::nano>(Clock::now() - t0).count() / static_cast<double>(n);
}

}  // namespace

UdotRace race_udot(const GeneratedEngine& engine, KanegenFunctionPtr first, KanegenFunctionPtr second,
                   const State& s, int rounds, double slice_us) {
  const int nu = engine.model().nu;
  std::vector<double> out1(static_cast<std::size_t>(std::max(nu, 1))), out2(out1.size());
  UdotRace r;
  // agreement at the state and at one with every speed and input moved (a body at rest with no inputs has
  // u-dot 0 from nearly any code), relative to the largest entry of either
  State moved = s;
  for (int i = 0; i < nu; ++i) moved.u(i) += 0.1 * (1 + i % 3), moved.tau(i) += 0.05 * (1 + i % 2);
  std::vector<double> a[2], b[2];
  double scale = 1e-300;
  for (int k = 0; k < 2; ++k) {
    const State& at = k == 0 ? s : moved;
    a[k].resize(out1.size()), b[k].resize(out1.size());
    const int st1 = engine.call_udot(first, at.t, at.q, at.u, at.tau, a[k].data());
    const int st2 = engine.call_udot(second, at.t, at.q, at.u, at.tau, b[k].data());
    if (k == 0) r.first_status = st1, r.second_status = st2;
    for (int i = 0; i < nu; ++i) scale = std::max(scale, std::abs(a[k][static_cast<std::size_t>(i)]));
  }
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < nu; ++i) {
      const double d = std::abs(a[k][static_cast<std::size_t>(i)] - b[k][static_cast<std::size_t>(i)]) / scale;
      r.max_rel_diff = std::max(r.max_rel_diff, std::isnan(d) ? std::numeric_limits<double>::infinity() : d);
    }
  const std::function<void()> calls[2] = {
      [&] { engine.call_udot(first, s.t, s.q, s.u, s.tau, out1.data()); },
      [&] { engine.call_udot(second, s.t, s.q, s.u, s.tau, out2.data()); }};
  const long n[2] = {calls_per_slice(calls[0], slice_us), calls_per_slice(calls[1], slice_us)};
  double best[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  for (int k = 0; k < rounds; ++k)
    for (int which = 0; which < 2; ++which) {
      // alternate which goes first, so that neither always follows the other
      const int f = (k % 2 == 0) ? which : 1 - which;
      best[f] = std::min(best[f], slice_ns(calls[f], n[f]));
    }
  r.first_ns = best[0];
  r.second_ns = best[1];
  return r;
}

bool second_wins(const UdotRace& r, double tol, double margin) {
  return r.first_status == 0 && r.second_status == 0 && r.max_rel_diff <= tol &&
         r.second_ns < (1.0 - margin) * r.first_ns;
}

}  // namespace kanegen
