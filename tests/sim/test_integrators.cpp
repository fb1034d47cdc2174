// Tests for sim/integrators.{hpp,cpp}: accuracy against exact solutions,
// output placement, RK4 order, stiffness handling, failures, projection.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/integrators.hpp"

using namespace kanegen;

namespace {

const std::vector<IntegratorKind> kAllKinds = {IntegratorKind::cvode_bdf, IntegratorKind::cvode_adams,
                                               IntegratorKind::arkode_erk, IntegratorKind::arkode_dirk,
                                               IntegratorKind::rk4,       IntegratorKind::dopri5,
                                               IntegratorKind::rkf78};

struct Recorded {
  std::vector<double> t;
  std::vector<Eigen::VectorXd> x;
  OutputFn fn() {
    return [this](double tt, const Eigen::VectorXd& xx) {
      t.push_back(tt);
      x.push_back(xx);
      return true;
    };
  }
};

/// x'' = -w^2 x as [x, v]; exact: x = cos(w t), v = -w sin(w t).
OdeProblem oscillator(double w) {
  OdeProblem p;
  p.n = 2;
  p.rhs = [w](double, const double* x, double* xd) {
    xd[0] = x[1];
    xd[1] = -w * w * x[0];
    return 0;
  };
  return p;
}

Eigen::VectorXd oscillator_exact(double w, double t) {
  return Eigen::Vector2d(std::cos(w * t), -w * std::sin(w * t));
}

/// Stiff linear x' = A x with eigenvalues -1 (eigvec [1,1]) and -1e6 (eigvec [1,-1]).
constexpr double kLamSlow = -1.0, kLamFast = -1e6;
OdeProblem stiff_linear() {
  OdeProblem p;
  p.n = 2;
  const double a = 0.5 * (kLamSlow + kLamFast), b = 0.5 * (kLamSlow - kLamFast);
  p.rhs = [a, b](double, const double* x, double* xd) {
    xd[0] = a * x[0] + b * x[1];
    xd[1] = b * x[0] + a * x[1];
    return 0;
  };
  return p;
}
Eigen::VectorXd stiff_linear_exact(double t) {  // x0 = [2, 0]
  const double s = std::exp(kLamSlow * t), f = std::exp(kLamFast * t);
  return Eigen::Vector2d(s + f, s - f);
}

/// Robertson chemical kinetics (stiff, nonlinear).
OdeProblem robertson(bool with_jacobian) {
  OdeProblem p;
  p.n = 3;
  p.rhs = [](double, const double* y, double* yd) {
    yd[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
    yd[2] = 3e7 * y[1] * y[1];
    yd[1] = -yd[0] - yd[2];
    return 0;
  };
  if (with_jacobian) {
    p.jacobian = [](double, const double* y, const double*, double* J) {
      auto Jm = [J](int r, int c) -> double& { return J[c * 3 + r]; };  // column-major
      Jm(0, 0) = -0.04;
      Jm(0, 1) = 1e4 * y[2];
      Jm(0, 2) = 1e4 * y[1];
      Jm(2, 0) = 0.0;
      Jm(2, 1) = 6e7 * y[1];
      Jm(2, 2) = 0.0;
      for (int c = 0; c < 3; ++c) Jm(1, c) = -Jm(0, c) - Jm(2, c);
      return 0;
    };
  }
  return p;
}

IntegratorOptions opts(IntegratorKind kind, double rtol = 1e-10, double atol = 1e-12, double h = 1e-3) {
  IntegratorOptions o;
  o.kind = kind;
  o.rtol = rtol;
  o.atol = atol;
  o.h = h;
  return o;
}

}  // namespace

TEST_CASE("integrator names round-trip and unknown names are rejected", "[integrators]") {
  REQUIRE(integrator_names() ==
          std::vector<std::string>{"cvode-bdf", "cvode-adams", "arkode-erk", "arkode-dirk", "rk4", "cvode-bdf2", "dopri5",
                                   "rkf78", "auto"});
  for (auto k : kAllKinds) REQUIRE(integrator_from_string(to_string(k)) == k);
  try {
    integrator_from_string("euler");
    FAIL("expected std::invalid_argument");
  } catch (const std::invalid_argument& e) {
    REQUIRE(std::string(e.what()) ==
            "unknown integrator 'euler'; expected one of: cvode-bdf, cvode-adams, arkode-erk, arkode-dirk, rk4, cvode-bdf2, "
            "dopri5, rkf78, auto");
  }
}

TEST_CASE("harmonic oscillator: every integrator reaches the exact solution", "[integrators]") {
  const double w = 2.0, t0 = 0.0, t_end = 10.0, dt_out = 0.5;
  for (auto kind : kAllKinds) {
    DYNAMIC_SECTION(to_string(kind)) {
      // rk4 global error ~ C h^4: with h = 1e-3, w = 2 it is ~1e-11.
      Recorded rec;
      auto stats = integrate(oscillator(w), opts(kind), t0, Eigen::Vector2d(1.0, 0.0), t_end, dt_out, rec.fn());

      // Outputs at exactly t0 + k dt_out, first t0, last t_end, no duplicate.
      REQUIRE(rec.t.size() == 21);
      for (size_t k = 0; k < rec.t.size(); ++k) REQUIRE(rec.t[k] == t0 + static_cast<double>(k) * dt_out);
      REQUIRE(rec.t.front() == t0);
      REQUIRE(rec.t.back() == t_end);
      REQUIRE(rec.x.front() == Eigen::Vector2d(1.0, 0.0));

      const double err_end = (rec.x.back() - oscillator_exact(w, t_end)).norm();
      INFO(stats.summary() << ", error at t_end = " << err_end);
      REQUIRE(err_end < 1e-7);
      // Interpolated intermediate outputs are accurate too.
      for (size_t k = 0; k < rec.t.size(); ++k) REQUIRE((rec.x[k] - oscillator_exact(w, rec.t[k])).norm() < 1e-7);

      REQUIRE(stats.integrator == to_string(kind));
      REQUIRE(stats.steps > 0);
      REQUIRE(stats.rhs_evals >= stats.steps);
      REQUIRE(stats.wall_seconds >= 0.0);
      if (kind == IntegratorKind::rk4) {
        REQUIRE(stats.steps == 10000);
        REQUIRE(stats.rhs_evals == 4 * stats.steps);
      }
      REQUIRE(stats.summary().rfind(to_string(kind) + ": " + std::to_string(stats.steps) + " steps, " +
                                        std::to_string(stats.rhs_evals) + " rhs evals, " +
                                        std::to_string(stats.jac_evals) + " jac evals, ",
                                    0) == 0);
    }
  }
}

TEST_CASE("outputs: t_end not a multiple of dt_out, tolerance-scaled accuracy, early stop", "[integrators]") {
  const double w = 1.0;
  for (auto kind : kAllKinds) {
    DYNAMIC_SECTION(to_string(kind)) {
      Recorded rec;
      integrate(oscillator(w), opts(kind, 1e-6, 1e-9, 1e-2), 1.0, oscillator_exact(w, 1.0), 2.05, 0.25, rec.fn());
      REQUIRE(rec.t == std::vector<double>{1.0, 1.25, 1.5, 1.75, 2.0, 2.05});
      // Looser tolerance: error consistent with rtol 1e-6, not much better than it needs to be.
      for (size_t k = 0; k < rec.t.size(); ++k) REQUIRE((rec.x[k] - oscillator_exact(w, rec.t[k])).norm() < 1e-4);

      // Returning false stops the integration.
      std::vector<double> ts;
      integrate(oscillator(w), opts(kind), 0.0, Eigen::Vector2d(1, 0), 10.0, 1.0, [&](double t, const Eigen::VectorXd&) {
        ts.push_back(t);
        return t < 3.0;
      });
      REQUIRE(ts == std::vector<double>{0.0, 1.0, 2.0, 3.0});
    }
  }
}

TEST_CASE("rk4 is fourth-order convergent", "[integrators]") {
  const double w = 3.0, t_end = 5.0;
  std::vector<double> errors;
  for (double h : {0.04, 0.02, 0.01}) {
    Recorded rec;
    integrate(oscillator(w), opts(IntegratorKind::rk4, 0, 0, h), 0.0, Eigen::Vector2d(1, 0), t_end, t_end, rec.fn());
    errors.push_back((rec.x.back() - oscillator_exact(w, t_end)).norm());
  }
  for (size_t i = 0; i + 1 < errors.size(); ++i) {
    const double ratio = errors[i] / errors[i + 1];
    INFO("errors " << errors[i] << " -> " << errors[i + 1] << ", ratio " << ratio);
    REQUIRE(ratio > 12.0);
    REQUIRE(ratio < 20.0);
  }
}

TEST_CASE("rk4 shortens the last step to land on output times", "[integrators]") {
  // h = 0.3 does not divide dt_out = 0.5: steps 0.3, 0.2 per interval.
  Recorded rec;
  auto stats = integrate(oscillator(1.0), opts(IntegratorKind::rk4, 0, 0, 0.3), 0.0, Eigen::Vector2d(1, 0), 1.0, 0.5,
                         rec.fn());
  REQUIRE(rec.t == std::vector<double>{0.0, 0.5, 1.0});
  REQUIRE(stats.steps == 4);
  REQUIRE((rec.x.back() - oscillator_exact(1.0, 1.0)).norm() < 1e-3);
}

TEST_CASE("stiff linear system: implicit methods need far fewer steps than explicit", "[integrators]") {
  const double t_end = 1.0;
  const Eigen::Vector2d x0(2.0, 0.0);
  auto run = [&](IntegratorKind kind) {
    Recorded rec;
    auto stats = integrate(stiff_linear(), opts(kind, 1e-6, 1e-10), 0.0, x0, t_end, 0.1, rec.fn());
    const double err = (rec.x.back() - stiff_linear_exact(t_end)).norm();
    INFO(stats.summary() << ", error " << err);
    CHECK(err < 1e-5);
    return stats;
  };
  const auto bdf = run(IntegratorKind::cvode_bdf);
  const auto dirk = run(IntegratorKind::arkode_dirk);
  const auto erk = run(IntegratorKind::arkode_erk);
  INFO(bdf.summary() << "\n" << dirk.summary() << "\n" << erk.summary());
  REQUIRE(erk.steps > 10 * bdf.steps);
  REQUIRE(erk.steps > 10 * dirk.steps);
  // Explicit stability limit ~ 3.3 / 1e6 for Dormand-Prince: at least ~1e5 steps to t = 1.
  REQUIRE(erk.steps > 100000);
}

TEST_CASE("Robertson: FD and user Jacobians both reproduce the reference solution", "[integrators]") {
  const double t_end = 40.0;
  const Eigen::Vector3d y0(1.0, 0.0, 0.0);
  // Reference values at t = 40 (SUNDIALS cvRoberts_dns example).
  const Eigen::Vector3d ref(7.158270687e-01, 9.185534764e-06, 2.841637457e-01);
  for (auto kind : {IntegratorKind::cvode_bdf, IntegratorKind::arkode_dirk}) {
    DYNAMIC_SECTION(to_string(kind)) {
      Recorded fd, uj;
      const auto o = opts(kind, 1e-8, 1e-14);
      auto s_fd = integrate(robertson(false), o, 0.0, y0, t_end, 4.0, fd.fn());
      auto s_uj = integrate(robertson(true), o, 0.0, y0, t_end, 4.0, uj.fn());
      INFO("FD:   " << s_fd.summary() << "\nuser: " << s_uj.summary());
      const Eigen::Vector3d a = fd.x.back(), b = uj.x.back();
      for (int i = 0; i < 3; ++i) {
        REQUIRE(std::abs(a[i] - ref[i]) < 1e-6 * std::abs(ref[i]));
        REQUIRE(std::abs(b[i] - ref[i]) < 1e-6 * std::abs(ref[i]));
      }
      REQUIRE(std::abs(b.sum() - 1.0) < 1e-10);  // mass conservation
      REQUIRE(s_fd.jac_evals > 0);
      REQUIRE(s_uj.jac_evals > 0);
    }
  }
}

namespace {
/// Method of lines for u_t = u_xx - u^3 on (0, 1), u = 0 at both ends: n
/// interior points, stiff (eigenvalues down to ~ -4 (n+1)^2).
OdeProblem reaction_diffusion(int n, bool with_jacobian) {
  OdeProblem p;
  p.n = n;
  const double c = (n + 1.0) * (n + 1.0);
  p.rhs = [n, c](double, const double* u, double* ud) {
    for (int i = 0; i < n; ++i) {
      const double l = i > 0 ? u[i - 1] : 0.0, r = i + 1 < n ? u[i + 1] : 0.0;
      ud[i] = c * (l - 2.0 * u[i] + r) - u[i] * u[i] * u[i];
    }
    return 0;
  };
  if (with_jacobian) {
    p.jacobian = [n, c](double, const double* u, const double*, double* J) {
      Eigen::Map<Eigen::MatrixXd> Jm(J, n, n);
      Jm.setZero();
      for (int i = 0; i < n; ++i) {
        Jm(i, i) = -2.0 * c - 3.0 * u[i] * u[i];
        if (i > 0) Jm(i, i - 1) = c;
        if (i + 1 < n) Jm(i, i + 1) = c;
      }
      return 0;
    };
  }
  return p;
}
}  // namespace

TEST_CASE("user Jacobian: same answer as FD with fewer rhs evaluations", "[integrators]") {
  const int n = 30;
  Eigen::VectorXd u0(n);
  for (int i = 0; i < n; ++i) u0[i] = 2.0 * std::sin(M_PI * (i + 1.0) / (n + 1.0));
  for (auto kind : {IntegratorKind::cvode_bdf, IntegratorKind::arkode_dirk}) {
    DYNAMIC_SECTION(to_string(kind)) {
      Recorded fd, uj;
      const auto o = opts(kind, 1e-8, 1e-12);
      auto s_fd = integrate(reaction_diffusion(n, false), o, 0.0, u0, 0.5, 0.1, fd.fn());
      auto s_uj = integrate(reaction_diffusion(n, true), o, 0.0, u0, 0.5, 0.1, uj.fn());
      INFO("FD:   " << s_fd.summary() << "\nuser: " << s_uj.summary());
      const double scale = uj.x.back().cwiseAbs().maxCoeff();
      REQUIRE(scale > 1e-3);  // still a meaningful solution at t_end
      REQUIRE((fd.x.back() - uj.x.back()).cwiseAbs().maxCoeff() < 1e-6 * scale);
      REQUIRE(s_fd.jac_evals > 0);
      REQUIRE(s_uj.jac_evals > 0);
      // FD costs n rhs evaluations per Jacobian.
      REQUIRE(s_fd.rhs_evals >= n * s_fd.jac_evals);
      REQUIRE(s_uj.rhs_evals < s_fd.rhs_evals);
    }
  }
}

TEST_CASE("failure: rhs returning NaN after t = 1", "[integrators]") {
  OdeProblem p;
  p.n = 2;
  p.rhs = [](double t, const double* x, double* xd) {
    const double nan = t > 1.0 ? std::numeric_limits<double>::quiet_NaN() : 1.0;
    xd[0] = -x[0] * nan;
    xd[1] = -2.0 * x[1] * nan;
    return 0;
  };
  for (auto kind : kAllKinds) {
    DYNAMIC_SECTION(to_string(kind)) {
      Recorded rec;
      try {
        integrate(p, opts(kind, 1e-8, 1e-10, 1e-3), 0.0, Eigen::Vector2d(1, 1), 3.0, 0.1, rec.fn());
        FAIL("expected IntegrationError");
      } catch (const IntegrationError& e) {
        INFO(e.what());
        REQUIRE(e.t <= 1.0);
        // ERKStep (SUNDIALS 6.4) cannot recover from rhs failures: it stops at
        // the last step accepted before t = 1 (one step of ~0.01 earlier).
        REQUIRE(e.t > (kind == IntegratorKind::arkode_erk ? 0.95 : 0.999));
        REQUIRE(e.x.size() == 2);
        REQUIRE(e.x.allFinite());
        REQUIRE(std::abs(e.x[0] - std::exp(-e.t)) < 1e-5);  // the state at e.t
        REQUIRE(std::string(e.what()).find("non-finite") != std::string::npos);
        REQUIRE(std::string(e.what()).find("state = [") != std::string::npos);
      }
      REQUIRE(rec.t.back() <= 1.0);  // outputs before the failure were delivered
      REQUIRE(rec.t.size() >= 10);
    }
  }
}

TEST_CASE("failure: finite-time blow-up x' = x^2 (x = 1/(1-t))", "[integrators]") {
  OdeProblem p;
  p.n = 1;
  p.rhs = [](double, const double* x, double* xd) {
    xd[0] = x[0] * x[0];
    return 0;
  };
  for (auto kind : kAllKinds) {
    DYNAMIC_SECTION(to_string(kind)) {
      auto o = opts(kind, 1e-8, 1e-10, 1e-3);
      o.max_steps = 200000;
      try {
        integrate(p, o, 0.0, Eigen::VectorXd::Ones(1), 2.0, 0.5, {});
        FAIL("expected IntegrationError");
      } catch (const IntegrationError& e) {
        INFO(e.what());
        if (kind == IntegratorKind::rk4) {
          // Fixed step: steps over the singularity and overflows within a few steps.
          REQUIRE(e.t > 0.99);
          REQUIRE(e.t < 1.01);
        } else {
          // Adaptive: the step size collapses at the (numerical) blow-up time,
          // which differs from the exact t = 1 by the accumulated global error:
          // CVODE stops before 1, ARKODE's more accurate RK solution ~1e-9 after.
          REQUIRE(e.t > 0.999);
          REQUIRE(e.t < 1.0 + 1e-6);
          if (kind == IntegratorKind::cvode_bdf || kind == IntegratorKind::cvode_adams) REQUIRE(e.t < 1.0);
          REQUIRE(e.x[0] > 1e6);
          REQUIRE(std::string(e.what()).find("step size underflow") != std::string::npos);
        }
      }
    }
  }
}

TEST_CASE("failure: max_steps exhausted reports too much work", "[integrators]") {
  for (auto kind : kAllKinds) {
    DYNAMIC_SECTION(to_string(kind)) {
      auto o = opts(kind);
      o.max_steps = 50;
      Recorded rec;
      try {
        integrate(oscillator(2.0), o, 0.0, Eigen::Vector2d(1, 0), 10.0, 0.01, rec.fn());
        FAIL("expected IntegrationError");
      } catch (const IntegrationError& e) {
        INFO(e.what());
        REQUIRE(std::string(e.what()).find("too much work") != std::string::npos);
        REQUIRE(e.t > 0.0);
        REQUIRE(e.t < 10.0);
        REQUIRE((e.x - oscillator_exact(2.0, e.t)).norm() < 1e-6);  // state consistent with reported time
      }
      REQUIRE(rec.t.size() >= 1);
    }
  }
}

TEST_CASE("exceptions thrown by the rhs propagate unchanged", "[integrators]") {
  OdeProblem p = oscillator(1.0);
  p.rhs = [](double t, const double* x, double* xd) -> int {
    if (t > 0.5) throw std::domain_error("model left its valid domain");
    xd[0] = x[1];
    xd[1] = -x[0];
    return 0;
  };
  for (auto kind : kAllKinds) {
    DYNAMIC_SECTION(to_string(kind)) {
      REQUIRE_THROWS_MATCHES(integrate(p, opts(kind), 0.0, Eigen::Vector2d(1, 0), 2.0, 0.1, {}), std::domain_error,
                             Catch::Matchers::Message("model left its valid domain"));
    }
  }
}

TEST_CASE("projection is applied to output states", "[integrators]") {
  // Rotation on the unit circle; loose tolerances / big RK4 step make the norm drift without projection.
  OdeProblem p;
  p.n = 2;
  p.rhs = [](double, const double* x, double* xd) {
    xd[0] = -x[1];
    xd[1] = x[0];
    return 0;
  };
  long project_calls = 0;
  OdeProblem pp = p;
  pp.project = [&project_calls](double* x) {
    ++project_calls;
    const double r = std::hypot(x[0], x[1]);
    x[0] /= r;
    x[1] /= r;
  };
  for (auto kind : kAllKinds) {
    DYNAMIC_SECTION(to_string(kind)) {
      const auto o = opts(kind, 1e-3, 1e-6, 0.5);
      Recorded raw, proj;
      integrate(p, o, 0.0, Eigen::Vector2d(1, 0), 20.0, 0.5, raw.fn());
      project_calls = 0;
      auto stats = integrate(pp, o, 0.0, Eigen::Vector2d(1, 0), 20.0, 0.5, proj.fn());
      double max_drift_raw = 0, max_drift_proj = 0;
      for (const auto& x : raw.x) max_drift_raw = std::max(max_drift_raw, std::abs(x.norm() - 1.0));
      for (const auto& x : proj.x) max_drift_proj = std::max(max_drift_proj, std::abs(x.norm() - 1.0));
      INFO("drift without projection " << max_drift_raw << ", with " << max_drift_proj);
      // (rkf78, 8th order with steps ending on the outputs, drifts less: 1.3e-8 here)
      REQUIRE(max_drift_raw > (kind == IntegratorKind::rkf78 ? 1e-9 : 1e-6));
      REQUIRE(max_drift_proj < 1e-14);
      // The phase is still right (projection only removes the radial error).
      REQUIRE(std::abs(std::atan2(proj.x.back()[1], proj.x.back()[0]) - std::remainder(20.0, 2 * M_PI)) < 0.05);
      if (kind == IntegratorKind::rk4) {
        REQUIRE(project_calls == stats.steps + static_cast<long>(proj.t.size()));  // every step + every output
      } else {
        REQUIRE(project_calls == static_cast<long>(proj.t.size()));
      }
    }
  }
}

TEST_CASE("invalid arguments are rejected", "[integrators]") {
  const auto p = oscillator(1.0);
  REQUIRE_THROWS_AS(integrate(p, opts(IntegratorKind::cvode_bdf), 0.0, Eigen::Vector3d(1, 0, 0), 1.0, 0.1, {}),
                    std::invalid_argument);
  REQUIRE_THROWS_AS(integrate(p, opts(IntegratorKind::cvode_bdf), 0.0, Eigen::Vector2d(1, 0), 1.0, 0.0, {}),
                    std::invalid_argument);
  REQUIRE_THROWS_AS(integrate(p, opts(IntegratorKind::cvode_bdf), 1.0, Eigen::Vector2d(1, 0), 0.0, 0.1, {}),
                    std::invalid_argument);
  REQUIRE_THROWS_AS(integrate(p, opts(IntegratorKind::rk4, 0, 0, 0.0), 0.0, Eigen::Vector2d(1, 0), 1.0, 0.1, {}),
                    std::invalid_argument);
}

TEST_CASE("cvode-bdf2 steps over a lightly damped stiff oscillation that drives cvode-bdf to small steps",
          "[integrators]") {
  // x'' + 2 zeta w x' + w^2 x = y with w = 2 pi 1000 rad/s, zeta = 0.01, driven
  // quasi-statically by a slow variable y' = -y: like a stiff flexible mode
  // deflected by slow rigid motion, its amplitude stays below atol, so only
  // stability limits the step. An A-stable method steps on the slow scale;
  // BDF orders 3-5 are not A-stable near the imaginary axis.
  const double w = 2 * M_PI * 1000, zeta = 0.01;
  OdeProblem p;
  p.n = 3;
  p.rhs = [&](double, const double* x, double* f) {
    f[0] = x[1];
    f[1] = -w * w * x[0] - 2 * zeta * w * x[1] + x[2];
    f[2] = -x[2];
    return 0;
  };
  Eigen::VectorXd x0(3);
  x0 << 1.0 / (w * w), 0.0, 1.0;  // starts at the static deflection
  auto run = [&](IntegratorKind kind) {
    IntegratorOptions o;
    o.kind = kind;
    o.rtol = 1e-8;
    o.atol = 1e-10;
    double y_end = 0;
    const IntegratorStats s = integrate(p, o, 0.0, x0, 5.0, 5.0, [&](double, const Eigen::VectorXd& x) {
      y_end = x(2);
      return true;
    });
    CHECK(y_end == Approx(std::exp(-5.0)).epsilon(1e-5));
    return s.steps;
  };
  const long bdf = run(IntegratorKind::cvode_bdf), bdf2 = run(IntegratorKind::cvode_bdf2);
  INFO("cvode-bdf " << bdf << " steps, cvode-bdf2 " << bdf2 << " steps");
  CHECK(bdf2 * 5 < bdf);
}
