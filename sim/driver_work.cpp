#include "sim/driver_work.hpp"

#include "sim/work_precision.hpp"

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

EnergyBalance energy_balance(const std::vector<double>& t, const std::vector<double>& E,
                             const std::vector<double>& P, double scale) {
  EnergyBalance out;
  if (t.size() < 2) return out;
  if (!(scale > 0)) scale = 1.0;
  // W on every row, and on every other one (to gauge the quadrature)
  std::vector<double> t2, P2;
  for (std::size_t k = 0; k < t.size(); k += 2) {
    t2.push_back(t[k]);
    P2.push_back(P[k]);
  }
  double W = 0.0, W2 = 0.0, worst = 0.0, quad = 0.0;
  for (std::size_t k = 1; k < t.size(); ++k) {
    W += interval_integral(t, P, k - 1);
    worst = std::max(worst, std::abs(E[k] - E[0] - W));
    if (k % 2 == 0) {
      W2 += interval_integral(t2, P2, k / 2 - 1);
      quad = std::max(quad, std::abs(W - W2) / 15.0);
    }
  }
  out.residual = worst / scale;
  if (t.size() >= 5) out.quadrature = quad / scale;  // both rules fourth order only from 4 points each
  return out;
}

void DriverWorkMeter::new_segment(const LockSet& locks) {
  engine_.set_locks(locks);
  segments_.emplace_back();
}

void DriverWorkMeter::add(double t, const VecX& q, const VecX& u) {
  Segment& s = segments_.back();
  if (!s.t.empty() && t <= s.t.back()) return;  // an event's second row: it starts the next segment
  const EnergyValues e = engine_.energy(t, q, u);
  s.t.push_back(t);
  s.E.push_back(e.T + e.V);
  s.P.push_back(driver_power(engine_, t, q, u, tau_));
  s.scale = std::max(s.scale, e.T + std::abs(e.V));
}

EnergyBalance DriverWorkMeter::balance() const {
  EnergyBalance out;
  for (const Segment& s : segments_) {
    const EnergyBalance b = energy_balance(s.t, s.E, s.P, s.scale);
    out.residual = bench::worse_measure(out.residual, b.residual);
    out.quadrature = bench::worse_measure(out.quadrature, b.quadrature);
  }
  return out;
}

}  // namespace kanegen
