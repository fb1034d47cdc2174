#include "sim/driver_work.hpp"

#include <algorithm>
#include <cmath>

namespace kanegen {

double driver_power(Engine& engine, double t, const VecX& q, const VecX& u, const VecX& tau) {
  const Model& m = engine.model();
  VecX ud;
  engine.udot(t, q, u, tau, ud);
  std::vector<Reaction> r;
  engine.reactions(t, q, u, ud, r);
  double P = 0.0;
  for (std::size_t i = 0; i < m.bodies.size(); ++i) {
    const Joint& j = m.bodies[i].joint;
    if (!j.prescribed()) continue;
    // J to B is the one motion along axis_J, which it leaves unchanged: the axis in B is axis_J
    const double along = j.type == JointType::revolute ? r[i].torque_B.dot(j.axis_J) : r[i].force_B.dot(j.axis_J);
    P += along * j.motion->at(t).f_dot;
  }
  return P;
}

namespace {

/// Integral over [t[i], t[i+1]] of the cubic through the samples i-1..i+2 (clamped to the ends).
double interval_integral(const std::vector<double>& t, const std::vector<double>& y, std::size_t i) {
  const std::size_t n = t.size();
  if (n < 4) return 0.5 * (y[i] + y[i + 1]) * (t[i + 1] - t[i]);
  const std::size_t a = std::min(i > 0 ? i - 1 : 0, n - 4);
  // Lagrange basis on t[a..a+3], each integrated exactly by 3-point Gauss-Legendre (degree 5)
  const double h = t[i + 1] - t[i], mid = 0.5 * (t[i] + t[i + 1]);
  const double g[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, w[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  double s = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double x = mid + 0.5 * h * g[k];
    double p = 0.0;
    for (std::size_t l = a; l < a + 4; ++l) {
      double basis = 1.0;
      for (std::size_t o = a; o < a + 4; ++o)
        if (o != l) basis *= (x - t[o]) / (t[l] - t[o]);
      p += y[l] * basis;
    }
    s += w[k] * p;
  }
  return 0.5 * h * s;
}

}  // namespace

EnergyBalance energy_balance(Engine& engine, const bench::Trajectory& seg, const VecX& tau) {
  const Model& m = engine.model();
  EnergyBalance out;
  // distinct times only (an event's two rows share one; none inside a segment, but be safe)
  std::vector<double> t, P, E;
  double scale = 0.0;
  for (std::size_t k = 0; k < seg.t.size(); ++k) {
    if (!t.empty() && seg.t[k] <= t.back()) continue;
    const VecX q = seg.x[k].head(m.nq), u = seg.x[k].tail(m.nu);
    const EnergyValues e = engine.energy(seg.t[k], q, u);
    t.push_back(seg.t[k]);
    E.push_back(e.T + e.V);
    P.push_back(driver_power(engine, seg.t[k], q, u, tau));
    scale = std::max(scale, e.T + std::abs(e.V));
  }
  if (t.size() < 2) return out;
  if (!(scale > 0)) scale = 1.0;
  // W on every sample, and on every other one (to gauge the quadrature)
  std::vector<double> t2, P2;
  for (std::size_t k = 0; k < t.size(); k += 2) {
    t2.push_back(t[k]);
    P2.push_back(P[k]);
  }
  double W = 0.0, W2 = 0.0, worst = 0.0, quad = 0.0;
  for (std::size_t k = 1; k < t.size(); ++k) {
    W += interval_integral(t, P, k - 1);
    worst = std::max(worst, std::abs(E[k] - E[0] - W));
    if (k % 2 == 0 && t2.size() >= 2) {
      W2 += interval_integral(t2, P2, k / 2 - 1);
      quad = std::max(quad, std::abs(W - W2) / 15.0);
    }
  }
  out.residual = worst / scale;
  out.quadrature = quad / scale;
  return out;
}

}  // namespace kanegen
