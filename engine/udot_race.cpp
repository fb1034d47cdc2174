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
  return race_udots(engine, {first, second}, s, rounds, slice_us).front();
}

std::vector<UdotRace> race_udots(const GeneratedEngine& engine, const std::vector<KanegenFunctionPtr>& fns,
                                 const State& s, int rounds, double slice_us) {
  const std::size_t n_fns = fns.size();
  if (n_fns < 2) return {};
  const int nu = engine.model().nu;
  const std::size_t n_out = static_cast<std::size_t>(std::max(nu, 1));
  std::vector<UdotRace> races(n_fns - 1);
  // agreement at the state and at one with every speed and input moved (a body at rest with no inputs has
  // u-dot 0 from nearly any code), relative to the largest entry of the reference's
  State moved = s;
  for (int i = 0; i < nu; ++i) moved.u(i) += 0.1 * (1 + i % 3), moved.tau(i) += 0.05 * (1 + i % 2);
  std::vector<std::vector<double>> out(n_fns, std::vector<double>(n_out));
  std::vector<std::vector<double>> by[2];
  double scale = 1e-300;
  for (int k = 0; k < 2; ++k) {
    const State& at = k == 0 ? s : moved;
    by[k].assign(n_fns, std::vector<double>(n_out));
    for (std::size_t f = 0; f < n_fns; ++f) {
      const int status = engine.call_udot(fns[f], at.t, at.q, at.u, at.tau, by[k][f].data());
      if (k == 0 && f == 0)
        for (UdotRace& r : races) r.first_status = status;
      else if (k == 0)
        races[f - 1].second_status = status;
      if (f == 0)  // the reference's outputs only: a candidate's huge ones must not hide another's error
        for (int i = 0; i < nu; ++i) scale = std::max(scale, std::abs(by[k][f][static_cast<std::size_t>(i)]));
    }
  }
  for (int k = 0; k < 2; ++k)
    for (std::size_t f = 1; f < n_fns; ++f)
      for (std::size_t i = 0; i < static_cast<std::size_t>(nu); ++i) {
        const double d = std::abs(by[k][0][i] - by[k][f][i]) / scale;
        UdotRace& r = races[f - 1];
        r.max_rel_diff = std::max(r.max_rel_diff, std::isnan(d) ? std::numeric_limits<double>::infinity() : d);
      }
  std::vector<std::function<void()>> calls;
  for (std::size_t f = 0; f < n_fns; ++f)
    calls.emplace_back([&, f] { engine.call_udot(fns[f], s.t, s.q, s.u, s.tau, out[f].data()); });
  std::vector<long> n;
  for (const auto& c : calls) n.push_back(calls_per_slice(c, slice_us));
  std::vector<double> best(n_fns, std::numeric_limits<double>::infinity());
  for (int k = 0; k < rounds; ++k)
    for (std::size_t which = 0; which < n_fns; ++which) {
      // the order turned by one each round and reversed every other round, so that none always follows the
      // same other
      const std::size_t pos = k % 2 == 0 ? which : n_fns - 1 - which;
      const std::size_t f = (pos + static_cast<std::size_t>(k)) % n_fns;
      best[f] = std::min(best[f], slice_ns(calls[f], n[f]));
    }
  for (std::size_t f = 1; f < n_fns; ++f) races[f - 1].first_ns = best[0], races[f - 1].second_ns = best[f];
  return races;
}

bool second_wins(const UdotRace& r, double tol, double margin) {
  return r.first_status == 0 && r.second_status == 0 && r.max_rel_diff <= tol &&
         r.second_ns < (1.0 - margin) * r.first_ns;
}

}  // namespace kanegen
