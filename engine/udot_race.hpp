// Which of two builds of one model's u-dot is faster on this machine, measured
// the way the speed report measures (bench/bench_support.hpp): interleaved
// slices, the least per-call time of each. The JIT uses it to keep a second
// compiler's u-dot only when it is measured faster (jit.cpp).
#pragma once

#include "engine/generated_engine.hpp"
#include <vector>

#include "model/state_io.hpp"

namespace kanegen {

struct UdotRace {
  double first_ns = 0, second_ns = 0;  ///< least time per call of each
  /// largest |difference| of their outputs over the largest |first's output| (the reference's), at the state
  /// and at one with moved speeds and inputs
  double max_rel_diff = 0;
  int first_status = 0, second_status = 0;
};

/// Times `first` and `second` (u-dot functions of `engine`'s model, e.g. its own and another build's)
/// at `state`, interleaved: `rounds` slices of about `slice_us` microseconds each per function.
UdotRace race_udot(const GeneratedEngine& engine, KanegenFunctionPtr first, KanegenFunctionPtr second,
                   const State& state, int rounds = 9, double slice_us = 300);

/// Times `fns[0]` (the reference, e.g. the library's own u-dot) and every other of `fns` in ONE race: each
/// round times a slice of every function, in an order turned by one each round, so that a spell of load on
/// the machine falls on all of them alike (pairwise races each against the reference, one after the other,
/// let a spell during one of them pick the wrong winner). Entry i-1 of the result is fns[i] against fns[0].
std::vector<UdotRace> race_udots(const GeneratedEngine& engine, const std::vector<KanegenFunctionPtr>& fns,
                                 const State& state, int rounds = 21, double slice_us = 300);

/// Whether the second of a race is worth using: its outputs agree with the first's to `tol` (relative)
/// and it is faster by more than `margin` (0.05: 5 %), so that noise does not flip the choice.
bool second_wins(const UdotRace& r, double tol = 1e-9, double margin = 0.05);

}  // namespace kanegen
