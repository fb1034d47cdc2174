// The joint angles' sin and cos of the generated code (templates/joint_sincos.inc,
// issue 38 item 3): computed in one batch, two angles at a time, with an
// accuracy no worse than the library's. Measured against sinl/cosl (64-bit
// mantissa, ~2^-11 of a double's ulp) on random arguments and next to
// multiples of pi/2, where the result is small and the argument reduction
// decides; beyond 1e5 rad, inf and NaN the library's own values.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace joint_sincos_test {
#include "templates/joint_sincos.inc"
}

// The same batch built for AVX2 with FMA, as the JIT's dispatched clones are: GCC contracts a product and a
// sum into a fused multiply-add by default, which must not break the exact steps (kanegen_rounded).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define JOINT_SINCOS_TEST_FMA 1
#pragma GCC push_options
#pragma GCC target("avx2,fma")
#pragma GCC optimize("O2", "fp-contract=fast")  // as the JIT builds it (the suite's own build is -O1)
namespace joint_sincos_fma {
#include "templates/joint_sincos.inc"
}
#pragma GCC pop_options
#endif

namespace {

/// |v - ref| in units of the last place of the double nearest ref.
double ulps(double v, long double ref) {
  const double rd = static_cast<double>(ref);
  const double u = std::nextafter(std::fabs(rd), INFINITY) - std::fabs(rd);
  return static_cast<double>(std::fabs(static_cast<long double>(v) - ref) / u);
}

struct Worst {
  double ours = 0, library = 0;
};

/// The largest error of the batch and of the library's sin and cos over `xs`.
Worst worst_over(const std::vector<double>& xs) {
  std::vector<double> s(xs.size()), c(xs.size());
  joint_sincos_test::kanegen_sincos_n(xs.data(), s.data(), c.data(), static_cast<int>(xs.size()));
  Worst w;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    const long double x = xs[i], rs = sinl(x), rc = cosl(x);
    w.ours = std::max({w.ours, ulps(s[i], rs), ulps(c[i], rc)});
    w.library = std::max({w.library, ulps(std::sin(xs[i]), rs), ulps(std::cos(xs[i]), rc)});
  }
  return w;
}

}  // namespace

TEST_CASE("joint angles' sin and cos: within 0.51 ulp, no worse than the library's", "[generator][sincos]") {
  std::mt19937_64 rng(2026);
  for (const double range : {1e-3, 3.2, 20.0, 1e5}) {
    INFO("arguments in [-" << range << ", " << range << "]");
    std::uniform_real_distribution<double> d(-range, range);
    std::vector<double> xs(400001);  // an odd count: the last angle goes alone
    for (double& x : xs) x = d(rng);
    const Worst w = worst_over(xs);
    CHECK(w.ours <= 0.51);
    CHECK(w.ours <= w.library + 1e-3);
  }
  // next to multiples of pi/2 (the nearest doubles and three steps either side), up to 1e5 rad
  std::vector<double> near;
  for (int k = -63000; k <= 63000; k += 7) {
    double x = k * 1.5707963267948966;
    for (int step = 0; step < 3; ++step) x = std::nextafter(x, -INFINITY);
    for (int step = 0; step < 7; ++step, x = std::nextafter(x, INFINITY))
      if (std::fabs(x) <= 1e5) near.push_back(x);
  }
  const Worst w = worst_over(near);
  CHECK(w.ours <= 0.51);
  CHECK(w.ours <= w.library + 1e-3);
}

TEST_CASE("joint angles' sin and cos: the library's beyond 1e5 rad, for inf and NaN, any count", "[generator][sincos]") {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  // in pairs as the batch takes them: both in range, both out, and mixed (1e-300 with 2e5, NaN with 1.2)
  const std::vector<double> xs{1e5, -1e5, 1.0000001e5, -3e7, 1e300, inf,  -inf, nan,
                               0.0, -0.0, 1e-300,      2e5,  0.3,   -0.7, nan,  1.2, inf};
  std::vector<double> s(xs.size()), c(xs.size());
  joint_sincos_test::kanegen_sincos_n(xs.data(), s.data(), c.data(), static_cast<int>(xs.size()));
  for (std::size_t i = 0; i < xs.size(); ++i) {
    INFO("x = " << xs[i]);
    if (std::isnan(std::sin(xs[i]))) {
      CHECK(std::isnan(s[i]));
      CHECK(std::isnan(c[i]));
    } else if (std::fabs(xs[i]) > 1e5) {
      CHECK(s[i] == std::sin(xs[i]));  // the library's own
      CHECK(c[i] == std::cos(xs[i]));
    } else {
      CHECK(ulps(s[i], sinl(xs[i])) <= 0.51);
      CHECK(ulps(c[i], cosl(xs[i])) <= 0.51);
    }
  }
  // a lane in range gets the same value whether its pair's other lane is in range or not
  {
    const double in_pair[2] = {1.2, 0.1}, tiny_pair[2] = {0.2, 1e-300};
    double sp[2], cp[2], st[2], ct[2];
    joint_sincos_test::kanegen_sincos_n(in_pair, sp, cp, 2);
    joint_sincos_test::kanegen_sincos_n(tiny_pair, st, ct, 2);
    CHECK(s[15] == sp[0]);
    CHECK(c[15] == cp[0]);
    CHECK(s[10] == st[1]);
    CHECK(c[10] == ct[1]);
  }
  // one angle, three: the same values as in a longer batch
  for (const int n : {1, 3}) {
    std::vector<double> s1(static_cast<std::size_t>(n)), c1(static_cast<std::size_t>(n));
    joint_sincos_test::kanegen_sincos_n(xs.data() + 8, s1.data(), c1.data(), n);
    for (int i = 0; i < n; ++i) {
      CHECK(s1[static_cast<std::size_t>(i)] == s[8 + static_cast<std::size_t>(i)]);
      CHECK(c1[static_cast<std::size_t>(i)] == c[8 + static_cast<std::size_t>(i)]);
    }
  }
  // another number type (the generated code's dual numbers): its own sin and cos
  const long double xl[2] = {0.5L, -2.0L};
  long double sl[2], cl[2];
  joint_sincos_test::kanegen_sincos_n(xl, sl, cl, 2);
  CHECK(sl[1] == std::sin(-2.0L));
  CHECK(cl[0] == std::cos(0.5L));
}

#ifdef JOINT_SINCOS_TEST_FMA
TEST_CASE("joint angles' sin and cos built with fused multiply-adds: within 0.51 ulp too", "[generator][sincos]") {
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) {
    WARN("this CPU has no AVX2 and FMA: the fused build is not run");
    return;
  }
  std::mt19937_64 rng(2027);
  std::vector<double> xs;
  for (const double range : {0.2, 3.2, 1e5}) {
    std::uniform_real_distribution<double> d(-range, range);
    for (int k = 0; k < 300000; ++k) xs.push_back(d(rng));
  }
  std::vector<double> s(xs.size()), c(xs.size());
  joint_sincos_fma::kanegen_sincos_n(xs.data(), s.data(), c.data(), static_cast<int>(xs.size()));
  double worst = 0;
  for (std::size_t i = 0; i < xs.size(); ++i)
    worst = std::max({worst, ulps(s[i], sinl(xs[i])), ulps(c[i], cosl(xs[i]))});
  CHECK(worst <= 0.51);  // 1.0 when a fused multiply-add takes Veltkamp's or Dekker's product unrounded
}
#endif
