#include "engine/engine.hpp"

#include <fmt/format.h>

#include "engine/locks.hpp"
#include "model/parameters.hpp"

namespace kanegen {

void Engine::check_sizes(const VecX& q, std::initializer_list<const VecX*> nu_sized) const {
  bool ok = q.size() == model_.nq;
  for (const VecX* v : nu_sized) ok = ok && v->size() == model_.nu;
  if (!ok) {
    std::string sizes;
    for (const VecX* v : nu_sized) sizes += fmt::format(", {}", v->size());
    throw std::invalid_argument(fmt::format("{} engine: arguments of sizes {}{} for a model with nq = {}, nu = {}",
                                            name(), q.size(), sizes, model_.nq, model_.nu));
  }
}

void Engine::qdot(const VecX& q, const VecX& u, VecX& qd) {
  check_sizes(q, {&u});
  qd.resize(model_.nq);
  do_qdot(q, u, qd);
}

void Engine::mass_matrix(double t, const VecX& q, MatX& M) {
  check_sizes(q, {});
  M.resize(model_.nu, model_.nu);
  do_mass_matrix(t, q, M);
}

void Engine::forcing(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& F) {
  check_sizes(q, {&u, &tau});
  F.resize(model_.nu);
  do_forcing(t, q, u, tau, F);
}

void Engine::udot(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& ud) {
  check_sizes(q, {&u, &tau});
  ud.resize(model_.nu);
  if (locked_u_.empty()) {
    do_udot(t, q, u, tau, ud);
    return;
  }
  // the reduced system, from M and F at u_l = 0 (dynamics.md, Locks)
  u_lock_ = u;
  for (int k : locked_u_) u_lock_(k) = 0.0;
  M_lock_.resize(model_.nu, model_.nu);
  F_lock_.resize(model_.nu);
  do_mass_matrix(t, q, M_lock_);
  do_forcing(t, q, u_lock_, tau, F_lock_);
  reduced_udot(M_lock_, F_lock_, locked_u_, ud);
}

void Engine::set_locks(const LockSet& locks) {
  if (!locks.empty() && locks.size() != model_.bodies.size())
    throw std::invalid_argument(fmt::format("{} engine: a lock set of {} bodies for a model with {}", name(),
                                            locks.size(), model_.bodies.size()));
  for (std::size_t b = 0; b < locks.size(); ++b)
    if (locks[b] && !joint_can_lock(model_.bodies[b].joint))
      throw std::invalid_argument(fmt::format("{} engine: the joint of '{}' cannot be locked", name(),
                                              model_.bodies[b].name));
  locks_ = locks;
  locked_u_ = locked_speeds(model_, locks);
}

EnergyValues Engine::energy(double t, const VecX& q, const VecX& u) {
  check_sizes(q, {&u});
  return do_energy(t, q, u);
}

MomentumValues Engine::momentum(double t, const VecX& q, const VecX& u) {
  check_sizes(q, {&u});
  return do_momentum(t, q, u);
}

void Engine::reactions(double t, const VecX& q, const VecX& u, const VecX& ud, std::vector<Reaction>& out) {
  check_sizes(q, {&u, &ud});
  out.resize(model_.bodies.size());
  do_reactions(t, q, u, ud, out);
}

bool Engine::jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& J) {
  check_sizes(q, {&u, &tau});
  const int n = model_.nq + model_.nu;
  J.resize(n, n);
  if (!locked_u_.empty()) return false;
  return do_jacobian(t, q, u, tau, J);
}

void Engine::set_inputs(const VecX& w) {
  if (w.size() != model_.nw)
    throw std::invalid_argument(fmt::format("{} engine: {} input values for a model with {} named inputs", name(),
                                            w.size(), model_.nw));
  w_ = w;
}

VecX Engine::nominal_parameters(const Model& model) {
  VecX p(static_cast<Eigen::Index>(model.parameters.size()));
  for (std::size_t k = 0; k < model.parameters.size(); ++k) p(static_cast<Eigen::Index>(k)) = model.parameters[k].nominal;
  return p;
}

void Engine::set_parameters(const VecX& p) {
  if (p.size() != static_cast<Eigen::Index>(model_.parameters.size()))
    throw std::invalid_argument(fmt::format("{} engine: {} parameter values for a model with {} runtime parameters",
                                            name(), p.size(), model_.parameters.size()));
  Model m = model_;
  apply_parameters(m, model_.parameters, p);  // throws for a value out of its domain
  do_set_parameters(m);
  p_ = p;
  parameters_changed();
}

void Engine::outputs(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& y) {
  check_sizes(q, {&u, &tau});
  y.resize(model_.ny);
  if (locked_u_.empty()) {
    do_outputs(t, q, u, tau, y);
    return;
  }
  // the reduced system's: the free system's outputs at u_l = 0 with the locking torque applied; accelerations,
  // accelerometers and reactions then are those of the reduced motion
  tau_lock_ = locked_tau(t, q, u, tau);  // leaves u_lock_ (u_l = 0)
  do_outputs(t, q, u_lock_, tau_lock_, y);
}

VecX Engine::locked_tau(double t, const VecX& q, const VecX& u, const VecX& tau) {
  if (locked_u_.empty()) return tau;
  VecX ud;
  udot(t, q, u, tau, ud);  // the reduced u_dot; leaves M_lock_, F_lock_ (F with tau) and u_lock_ at this state
  VecX tau_star = tau;
  const VecX locking = M_lock_ * ud - F_lock_;  // zero on the free rows
  for (const int k : locked_u_) tau_star(k) += locking(k);
  return tau_star;
}

bool Engine::input_jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& B) {
  check_sizes(q, {&u, &tau});
  B.resize(model_.nu, model_.nw);
  return do_input_jacobian(t, q, u, tau, B);
}

bool Engine::output_jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& CD) {
  check_sizes(q, {&u, &tau});
  CD.resize(model_.ny, model_.nq + 2 * model_.nu + model_.nw);
  return do_output_jacobian(t, q, u, tau, CD);
}

}  // namespace kanegen
