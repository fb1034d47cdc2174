// The tolerances of the test suite, in one place, each with the reason for
// its size. Quantities are compared relative to their largest entry
// (rel_err in test_support.hpp), as the reference README asks.
#pragma once

namespace kanegen::test {

/// Double-precision evaluation of the same definition by two orderings of
/// the arithmetic (engine against engine, engine against the reference
/// vectors): sums of O(1) terms along a few-body chain, a few hundred ulps
/// of the largest term. The reference README reaches about 1e-12.
constexpr double kRoundoff = 1e-12;

/// Reactions are sums of body wrenches over whole subtrees, shifted to each
/// joint point: larger terms cancel, so one decade above kRoundoff.
constexpr double kReactionRoundoff = 1e-11;

/// A value copied or normalized, not computed (q as used, quaternion norms).
constexpr double kExact = 1e-15;

/// Central differences of step h ~ 1e-6 relative: O(h^2) truncation plus
/// O(eps / h) rounding, about 1e-9 relative; one hundred times that.
constexpr double kCentralDifference = 1e-7;

/// An invariant (energy, momentum) along an integration at relative
/// tolerance rtol: the global error is a few hundred local errors; the drift
/// may reach kDriftFactor * rtol.
constexpr double kDriftFactor = 1e3;

}  // namespace kanegen::test
