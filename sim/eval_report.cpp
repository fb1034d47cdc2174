#include "sim/eval_report.hpp"

namespace kanegen {

static nlohmann::ordered_json vec(const Eigen::Ref<const VecX>& v) {
  auto a = nlohmann::ordered_json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

nlohmann::ordered_json eval_report(Engine& engine, const State& state) {
  const Model& model = engine.model();
  VecX qdot, F, udot;
  MatX M;
  engine.qdot(state.q, state.u, qdot);
  engine.mass_matrix(state.t, state.q, M);
  engine.forcing(state.t, state.q, state.u, state.tau, F);
  engine.udot(state.t, state.q, state.u, state.tau, udot);

  nlohmann::ordered_json j;
  j["model"] = model.name;
  j["engine"] = engine.name();
  j["q_names"] = model.q_names;
  j["u_names"] = model.u_names;
  j["q"] = vec(state.q);
  j["u"] = vec(state.u);
  j["qdot"] = vec(qdot);
  auto rows = nlohmann::ordered_json::array();
  for (Eigen::Index r = 0; r < M.rows(); ++r) rows.push_back(vec(M.row(r).transpose()));
  j["M"] = rows;
  j["F"] = vec(F);
  j["udot"] = vec(udot);
  if (model.outputs.energy) {
    const EnergyValues E = engine.energy(state.t, state.q, state.u);
    j["energy"] = {{"T", E.T}, {"V", E.V}};
  }
  if (model.outputs.momentum) {
    const MomentumValues P = engine.momentum(state.t, state.q, state.u);
    j["momentum"] = {{"p", vec(P.p_N)}, {"H", vec(P.H_N)}};
  }
  if (model.outputs.reactions) {
    std::vector<Reaction> R;
    engine.reactions(state.t, state.q, state.u, udot, R);
    nlohmann::ordered_json jr;
    for (std::size_t i = 0; i < R.size(); ++i)
      jr[model.bodies[i].name] = {{"force", vec(R[i].force_B)}, {"torque", vec(R[i].torque_B)}};
    j["reactions"] = jr;
  }
  return j;
}

}  // namespace kanegen
