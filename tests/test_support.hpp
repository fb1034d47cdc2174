// Shared helpers and tolerances of the test suite.
#pragma once

#include <Eigen/Dense>
#include <string>

#include "jit.hpp"
#include "model.hpp"

namespace kanegen::test {

/// Rounding bound for quantities that are sums of O(1) terms evaluated in
/// double precision along a few-body chain: a few hundred ulps of the
/// largest term. The reference README reaches about 1e-12.
constexpr double kRoundoff = 1e-12;

inline std::string source_path(const std::string& rel) { return std::string(KANEGEN_SOURCE_DIR) + "/" + rel; }

/// max |a - b| / max(max|b|, floor): the error relative to the largest entry.
inline double rel_err(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double floor = 1e-300) {
  const double scale = std::max(b.cwiseAbs().maxCoeff(), floor);
  return (a - b).cwiseAbs().maxCoeff() / scale;
}

/// JIT options of the test suite: a cache inside the build tree, shared by
/// the test runs (KANEGEN_TEST_CACHE_DIR).
inline JitOptions jit_options() {
  JitOptions o;
  o.cache_dir = KANEGEN_TEST_CACHE_DIR;
  return o;
}

/// Writes `text` to a fresh temporary file with the given name and returns its path.
std::string write_temp(const std::string& name, const std::string& text);

}  // namespace kanegen::test
