#include "engine/engine.hpp"

#include <fmt/format.h>

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
  do_udot(t, q, u, tau, ud);
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
  return do_jacobian(t, q, u, tau, J);
}

void Engine::set_inputs(const VecX& w) {
  if (w.size() != model_.nw)
    throw std::invalid_argument(fmt::format("{} engine: {} input values for a model with {} named inputs", name(),
                                            w.size(), model_.nw));
  w_ = w;
}

void Engine::outputs(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& y) {
  check_sizes(q, {&u, &tau});
  y.resize(model_.ny);
  do_outputs(t, q, u, tau, y);
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
