// The spin-up beam benchmark (Kane, Ryan & Banerjee 1987; docs/spinup.md):
// L = 10 m, rhoA = 1.2 kg/m, EI = 1.4e4 N m^2 in the spin plane, hub spun up
// to 6 rad/s over 15 s by prescribed motion. On the committed models of
// models/spinup/ (written by scripts/spinup_benchmark.py), generic engine:
//  (a) without foreshortening the tip deflection diverges (6 rad/s is above
//      the first bending frequency, 3.80 rad/s);
//  (b) with foreshortening it stays bounded, with the reference peak;
//  (c) it agrees with the rigid-path reference, a chain of 20 rigid segments
//      with bending springs, whose centrifugal stiffening is exact.
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "sim/integrators.hpp"
#include "sim/simulate.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

constexpr double kLength = 10.0;     // m
constexpr double kSpinupEnd = 15.0;  // s
constexpr double kDt = 0.01;         // output interval, as the benchmark script

Model spinup_model(const std::string& name) { return load_model(test::source_path("models/spinup/" + name + ".yaml")); }

/// Tip deflection transverse to the beam in the hub frame, from the state x = [q; u].
using TipFn = std::function<double(const VecX& x)>;

/// The flexible beam: y of the last node's position rho + Phi eta + 1/2 gamma(eta).
TipFn beam_tip(const Model& model) {
  const Body& b = model.bodies[model.body_index("beam")];
  REQUIRE(b.flex);
  const FlexibleData& fd = *b.flex;
  const int k = static_cast<int>(fd.nodes.size()) - 1;  // the tip is the last node
  REQUIRE(fd.nodes[k].rho_B.x() == Approx(kLength));
  const int q0 = b.q_eta, m = fd.modes();
  const Eigen::RowVectorXd phi_y = fd.Phi.row(3 * k + 1);
  const MatX gamma_y = fd.has_second_order(k) && fd.Gamma[k][1].size() ? fd.Gamma[k][1] : MatX::Zero(m, m);
  const double rho_y = fd.nodes[k].rho_B.y();
  return [=](const VecX& x) {
    const VecX eta = x.segment(q0, m);
    return rho_y + phi_y.dot(eta) + 0.5 * eta.dot(gamma_y * eta);
  };
}

/// The chain seg1..segN (revolute about z, segment length L/N): y = sum_k l sin(theta_1 + ... + theta_k).
TipFn chain_tip(const Model& model) {
  std::vector<int> iq;
  for (int s = 1; model.q_index("seg" + std::to_string(s) + ".angle") >= 0; ++s)
    iq.push_back(model.q_index("seg" + std::to_string(s) + ".angle"));
  REQUIRE(iq.size() >= 2);
  const double ell = kLength / static_cast<double>(iq.size());
  return [=](const VecX& x) {
    double th = 0, y = 0;
    for (int i : iq) {
      th += x(i);
      y += ell * std::sin(th);
    }
    return y;
  };
}

struct TipHistory {
  std::vector<double> t, y;
  bool blew_up = false;        ///< the integration failed (or stopped) with a non-finite or huge state
  std::string failure;
  /// The sample of largest |y| for t <= t_max.
  std::pair<double, double> peak(double t_max) const {
    std::size_t best = 0;
    for (std::size_t i = 0; i < t.size() && t[i] <= t_max + 1e-9; ++i)
      if (std::abs(y[i]) > std::abs(y[best])) best = i;
    return {t[best], y[best]};
  }
  double max_abs(double t_from, double t_to) const {
    double a = 0;
    for (std::size_t i = 0; i < t.size(); ++i)
      if (t[i] >= t_from - 1e-9 && t[i] <= t_to + 1e-9) a = std::max(a, std::abs(y[i]));
    return a;
  }
};

/// Integrates the model from its initial state (generic engine, arkode-erk,
/// rtol 1e-10, atol 1e-12, as the benchmark script) to t_end, sampling the tip
/// every kDt; stops early once |tip| > stop_above.
TipHistory tip_history(const Model& model, const TipFn& tip, double t_end, double stop_above = 1e300) {
  GenericEngine engine(model);
  const State s0 = initial_state(model);
  std::string failure;
  OdeProblem ode = make_ode_problem(engine, s0.tau, &failure);
  IntegratorOptions opt;
  opt.kind = IntegratorKind::arkode_erk;
  opt.rtol = 1e-10;
  opt.atol = 1e-12;
  VecX x0(model.nq + model.nu);
  x0 << s0.q, s0.u;
  TipHistory h;
  try {
    integrate(ode, opt, 0.0, x0, t_end, kDt, [&](double t, const VecX& x) {
      const double y = tip(x);
      h.t.push_back(t);
      h.y.push_back(y);
      if (!std::isfinite(y) || std::abs(y) > stop_above) {
        h.blew_up = true;
        return false;
      }
      return true;
    });
  } catch (const IntegrationError& e) {
    h.blew_up = true;  // a blow-up that the integrator notices first counts as diverged too
    h.failure = e.what();
  }
  return h;
}

}  // namespace

TEST_CASE("spinup: the benchmark models are in-plane beams as documented", "[spinup][flexible][generic]") {
  // Guards against an EI[0]/EI[1] plane mix-up: every kept mode must move the
  // tip in y (in the spin plane, about body z), none along z.
  for (const char* name : {"spinup_beam_m2", "spinup_beam_m4", "spinup_beam_m4_nofs"}) {
    const Model model = spinup_model(name);
    const FlexibleData& fd = *model.bodies[model.body_index("beam")].flex;
    const int k = static_cast<int>(fd.nodes.size()) - 1;
    INFO(name);
    for (int j = 0; j < fd.modes(); ++j) {
      CHECK(std::abs(fd.Phi(3 * k + 1, j)) > 0.1);
      CHECK(std::abs(fd.Phi(3 * k + 2, j)) < 1e-9 * std::abs(fd.Phi(3 * k + 1, j)));
    }
    // first bending frequency 1.8751^2 sqrt(EI / (rhoA L^4)) = 3.7977 rad/s; 40 lumped elements: -0.03 %
    CHECK(2 * M_PI * fd.frequency_hz(0) == Approx(3.7977).epsilon(1e-3));
    CHECK(fd.has_second_order(k) == (std::string(name) != "spinup_beam_m4_nofs"));
  }
}

TEST_CASE("spinup: without foreshortening the tip deflection diverges", "[spinup][flexible][generic]") {
  // The conventional linear model loses its in-plane stiffness once Omega(t)
  // passes 3.80 rad/s (t = 8.51 s) and grows exponentially; measured: |tip|
  // passes 2 m at t = 7.93 s (-72 m at 10 s). 2 m is 3.5 times the bounded
  // model's peak, so this cannot pass by a bounded run.
  const Model model = spinup_model("spinup_beam_m4_nofs");
  const TipHistory h = tip_history(model, beam_tip(model), 14.0, 2.0);
  INFO("stopped at t = " << h.t.back() << ", tip " << h.y.back() << " m " << h.failure);
  CHECK(h.blew_up);
  CHECK(h.t.back() < 14.0);
  CHECK((h.failure.size() || std::abs(h.y.back()) > 2.0));
  CHECK(h.y.back() < 0);  // the tip lags the rotation
}

TEST_CASE("spinup: with foreshortening the tip stays bounded and peaks at -0.574 m", "[spinup][flexible][generic]") {
  // Reference peak: -0.574 m at 6.76 s (the colleague's converged chain,
  // notes/spinup_beam.md; the extrapolated N = 40/80 kanegen chain gives
  // -0.57375). Tolerance 1 % of the peak (5.7 mm), the sum of: modal
  // truncation (2 modes -0.5753, 4 modes -0.5761, 8 modes -0.5761), 40 vs 80
  // elements (0.04 %), and the flexible model's own truncation order (its
  // second-order kinematics carry the cubic terms in the deflection only in
  // part: +0.4 % against the exact chain; docs/spinup.md, section (c)). The
  // faults it is meant to catch are far outside it: no stiffening diverges, a
  // wrong rotation sense flips the sign, a factor 2 in Gamma moves the peak by
  // tens of percent, the out-of-plane EI gives micrometres.
  for (const char* name : {"spinup_beam_m2", "spinup_beam_m4"}) {
    const Model model = spinup_model(name);
    const TipHistory h = tip_history(model, beam_tip(model), 20.0);
    INFO(name << (h.failure.empty() ? "" : ": " + h.failure));
    REQUIRE_FALSE(h.blew_up);
    REQUIRE(h.t.back() == Approx(20.0));
    const auto [t_peak, peak] = h.peak(kSpinupEnd);
    INFO("peak " << peak << " m at t = " << t_peak << " s");
    CHECK(h.max_abs(0.0, 20.0) < 0.7);
    CHECK(peak == Approx(-0.574).epsilon(0.01));
    CHECK(t_peak == Approx(6.76).margin(0.05));  // the peak of the quasi-static response, sampled every 10 ms
    // The residual undamped oscillation after the spin-up: 3.6 mm (colleague,
    // chain and linear modal), measured 3.6-3.9 mm here; its amplitude depends
    // on the phase at which the acceleration ends, hence the wide band.
    const double residual = h.max_abs(kSpinupEnd, 20.0);
    INFO("residual max |tip| over 15-20 s " << residual << " m");
    CHECK(residual > 0.0025);
    CHECK(residual < 0.0050);
  }
}

TEST_CASE("spinup: the flexible beam agrees with the 20-segment rigid chain", "[spinup][flexible][generic]") {
  // The chain (clamp spring 2EI/l, joint springs EI/l) converges to second
  // order in 1/N: its N = 20 peak (-0.57526) is 0.26 % more flexible than the
  // extrapolated limit (-0.57375), and the 4-mode beam (-0.57609) is 0.4 %
  // more flexible than that limit (its truncation order). Peaks: within 1 %
  // (0.65 % of expected error + margin). Histories over 0-15 s: measured max
  // difference 1.3 mm, 0.23 % of the peak (the two errors partly cancel at
  // N = 20: against the N = 80 chain they are 0.41 % and 0.31 % of the peak);
  // bound 1.5 % (8.6 mm), which a 1-mode beam (0.83 % from this chain) still
  // meets and any fault of the stiffening (tens of percent) does not.
  const Model beam = spinup_model("spinup_beam_m4");
  const Model chain = spinup_model("spinup_chain20");
  REQUIRE(chain.nu == 20);
  const TipHistory hb = tip_history(beam, beam_tip(beam), kSpinupEnd);
  const TipHistory hc = tip_history(chain, chain_tip(chain), kSpinupEnd);
  REQUIRE_FALSE(hb.blew_up);
  REQUIRE_FALSE(hc.blew_up);
  REQUIRE(hb.t.size() == hc.t.size());
  const auto [tb, pb] = hb.peak(kSpinupEnd);
  const auto [tc, pc] = hc.peak(kSpinupEnd);
  double diff = 0, dt = 0;
  for (std::size_t i = 0; i < hb.t.size(); ++i) {
    dt = std::max(dt, std::abs(hb.t[i] - hc.t[i]));
    diff = std::max(diff, std::abs(hb.y[i] - hc.y[i]));
  }
  REQUIRE(dt < 1e-9);  // the same output times
  INFO("beam peak " << pb << " m at " << tb << " s; chain N = 20 peak " << pc << " m at " << tc
                    << " s; max |beam - chain| over 0-15 s " << diff << " m");
  CHECK(pb == Approx(pc).epsilon(0.01));
  CHECK(std::abs(tb - tc) <= 0.05);
  CHECK(diff < 0.015 * std::abs(pc));
}
