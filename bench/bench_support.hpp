// Shared by the benchmarks: a reproducible state near the model's initial one,
// and timing of calls interleaved in rounds.
#pragma once

#include <algorithm>
#include <chrono>
#include <functional>
#include <random>
#include <vector>

#include "model/model.hpp"
#include "model/state_io.hpp"

namespace kanegen::bench {

/// q0 perturbed by up to 0.3 per coordinate (quaternions renormalized), speeds
/// up to `speed` in magnitude, zero inputs.
inline State random_state(const Model& model, unsigned seed, double speed = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  State s = initial_state(model);
  for (int i = 0; i < model.nq; ++i) s.q(i) += 0.3 * U(rng);
  for (const auto& slot : model.quaternions) s.q.segment<4>(slot.q).normalize();
  for (int i = 0; i < model.nu; ++i) s.u(i) = speed * U(rng);
  return s;
}

/// Calls per batch so that one batch of f takes more than `seconds`
/// (doubling from 1, at most 2^26).
template <class F>
long batch_size(F&& f, double seconds) {
  using Clock = std::chrono::steady_clock;
  long n = 1;
  for (;;) {
    const auto t0 = Clock::now();
    for (long i = 0; i < n; ++i) f();
    if (std::chrono::duration<double>(Clock::now() - t0).count() > seconds || n > (1L << 26)) return n;
    n *= 2;
  }
}

/// Median ns per call of each function, timed interleaved: in each of
/// `rounds` rounds one batch of each (batches of about `batch_seconds`).
/// Per function, the median and the least of its `rounds` interleaved slices (ns per call): the least is
/// what the function costs when nothing else disturbs it (an outside rerun's figure), the median what a
/// loaded machine gives.
struct InterleavedTimes {
  std::vector<double> median, min;
};

inline InterleavedTimes interleaved_times(const std::vector<std::function<void()>>& fns, int rounds,
                                          double batch_seconds) {
  using Clock = std::chrono::steady_clock;
  std::vector<long> batch;
  for (const auto& f : fns) batch.push_back(batch_size(f, batch_seconds));
  std::vector<std::vector<double>> ns(fns.size());
  for (int r = 0; r < rounds; ++r)
    for (std::size_t e = 0; e < fns.size(); ++e) {
      const auto t0 = Clock::now();
      for (long i = 0; i < batch[e]; ++i) fns[e]();
      ns[e].push_back(std::chrono::duration<double, std::nano>(Clock::now() - t0).count() / batch[e]);
    }
  InterleavedTimes out;
  for (auto& v : ns) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    out.median.push_back(v[v.size() / 2]);
    out.min.push_back(*std::min_element(v.begin(), v.end()));
  }
  return out;
}

inline std::vector<double> interleaved_ns_per_call(const std::vector<std::function<void()>>& fns, int rounds,
                                                   double batch_seconds) {
  return interleaved_times(fns, rounds, batch_seconds).median;
}

}  // namespace kanegen::bench
