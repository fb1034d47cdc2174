#include "sim/crosscheck.hpp"

#include <random>

namespace kanegen {

double CrosscheckResult::tolerance(const std::string& quantity) {
  // Both engines agree to ~1e-13 on well-scaled models; reactions subtract
  // large inertia and gravity terms, u_dot's plain difference is amplified by
  // cond(M) (reported, not judged).
  if (quantity == "udot (relative)") return 1e300;
  if (quantity == "reactions" || quantity == "outputs") return 1e-11;
  return 1e-12;
}

bool CrosscheckResult::passed() const {
  for (const auto& [q, v] : worst)
    if (!(v <= tolerance(q))) return false;
  return true;
}

namespace {

double rel(const Eigen::Ref<const MatX>& a, const Eigen::Ref<const MatX>& b) {
  if (b.size() == 0) return 0.0;
  const double scale = std::max(b.cwiseAbs().maxCoeff(), 1e-300);
  return (a - b).cwiseAbs().maxCoeff() / scale;
}

}  // namespace

CrosscheckResult crosscheck(Engine& tested, Engine& reference, int samples, unsigned seed) {
  const Model& model = reference.model();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::normal_distribution<double> N(0.0, 1.0);
  CrosscheckResult r;
  auto note = [&](const std::string& k, double v) { r.worst[k] = std::max(r.worst[k], std::isnan(v) ? 1e300 : v); };
  for (int s = 0; s < samples; ++s) {
    VecX q = model.q0, u(model.nu), tau(model.nu);
    // Prescribed motion: times before, during and after a spin-up.
    const double t = model.has_prescribed() ? 10.0 + 11.0 * U(rng) : 0.0;
    for (const Body& b : model.bodies) {
      if (!b.joint.prescribed())
        random_coordinates(b.joint, [&] { return U(rng); }, [&] { return N(rng); }, q.data() + b.q_joint);
      for (int k = 0; k < b.n_modes(); ++k) q(b.q_eta + k) = 0.1 * U(rng);
      // In a central field the free roots are on orbit: ~7000 km from the central body
      if (model.central && b.parent < 0 && b.joint.type == JointType::free)
        q.segment<3>(b.q_joint) += 7.0e6 * Vec3(N(rng), N(rng), N(rng)).normalized();
    }
    for (int i = 0; i < model.nu; ++i) u(i) = U(rng), tau(i) = U(rng);
    VecX w(model.nw);
    for (int i = 0; i < model.nw; ++i) w(i) = U(rng);
    tested.set_inputs(w);
    reference.set_inputs(w);
    VecX qd_t, qd_r, F_t, F_r, ud_t, ud_r;
    MatX M_t, M_r;
    tested.qdot(q, u, qd_t);
    reference.qdot(q, u, qd_r);
    note("qdot", rel(qd_t, qd_r));
    tested.mass_matrix(t, q, M_t);
    reference.mass_matrix(t, q, M_r);
    note("M", rel(M_t, M_r));
    tested.forcing(t, q, u, tau, F_t);
    reference.forcing(t, q, u, tau, F_r);
    note("F", rel(F_t, F_r));
    tested.udot(t, q, u, tau, ud_t);
    reference.udot(t, q, u, tau, ud_r);
    note("udot (relative)", rel(ud_t, ud_r));
    note("udot (residual)", (M_r * ud_t - F_r).norm() / (M_r.norm() * ud_t.norm() + F_r.norm()));
    if (model.outputs.energy) {
      const EnergyValues a = tested.energy(t, q, u), b = reference.energy(t, q, u);
      note("energy", rel(Eigen::Vector2d(a.T, a.V), Eigen::Vector2d(b.T, b.V)));
    }
    if (model.outputs.momentum) {
      const MomentumValues a = tested.momentum(t, q, u), b = reference.momentum(t, q, u);
      Eigen::Matrix<double, 6, 1> x, y;
      x << a.p_N, a.H_N;
      y << b.p_N, b.H_N;
      note("momentum", rel(x, y));
    }
    if (model.outputs.reactions) {
      std::vector<Reaction> a, b;
      tested.reactions(t, q, u, ud_r, a);
      reference.reactions(t, q, u, ud_r, b);
      MatX x(6, a.size()), y(6, b.size());
      for (std::size_t i = 0; i < a.size(); ++i) {
        x.col(i) << a[i].force_B, a[i].torque_B;
        y.col(i) << b[i].force_B, b[i].torque_B;
      }
      note("reactions", rel(x, y));
    }
    if (model.ny > 0) {
      // reactions and accelerations among them: held to the reactions' tolerance
      VecX y_t, y_r;
      tested.outputs(t, q, u, tau, y_t);
      reference.outputs(t, q, u, tau, y_r);
      note("outputs", rel(y_t, y_r));
    }
    ++r.samples;
  }
  return r;
}

}  // namespace kanegen
