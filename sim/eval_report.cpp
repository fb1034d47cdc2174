#include "sim/eval_report.hpp"

#include <fmt/format.h>

#include <cmath>

namespace kanegen {

static nlohmann::ordered_json vec(const Eigen::Ref<const VecX>& v) {
  auto a = nlohmann::ordered_json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

namespace {

/// Throws NonFiniteResult naming the first non-finite entry of `v` (called `what`, entries named by `names`).
void require_finite(const Eigen::Ref<const MatX>& v, const std::string& what, const std::vector<std::string>& names,
                    const Model& model, const State& state) {
  for (Eigen::Index c = 0; c < v.cols(); ++c)
    for (Eigen::Index r = 0; r < v.rows(); ++r) {
      if (std::isfinite(v(r, c))) continue;
      std::string entry = what;
      if (v.cols() > 1)
        entry += fmt::format("[{}, {}]", r, c);
      else if (v.rows() > 1 || !names.empty())
        entry += fmt::format("[{}]", r);
      if (static_cast<std::size_t>(r) < names.size()) entry += " (" + names[r] + ")";
      std::string at = fmt::format("t = {:.17g}", state.t);
      for (int i = 0; i < model.nq; ++i) at += fmt::format(", {} = {:.17g}", model.q_names[i], state.q(i));
      for (int i = 0; i < model.nu; ++i) at += fmt::format(", {}' = {:.17g}", model.u_names[i], state.u(i));
      for (int i = 0; i < model.nu; ++i)
        if (state.tau(i) != 0.0) at += fmt::format(", tau {} = {:.17g}", model.u_names[i], state.tau(i));
      throw NonFiniteResult(fmt::format("{} is {} at the state {}; the state or the model's values overflow double "
                                        "precision",
                                        entry, v(r, c), at));
    }
}

}  // namespace

nlohmann::ordered_json eval_report(Engine& engine, const State& state) {
  const Model& model = engine.model();
  VecX qdot, F, udot;
  MatX M;
  engine.set_inputs(state.w);
  // with joints locked (STATE.json "locked"), u-dot and the reactions are the reduced system's
  const ScopedLocks locks(engine, state.locked);
  engine.qdot(state.q, state.u, qdot);
  engine.mass_matrix(state.t, state.q, M);
  engine.forcing(state.t, state.q, state.u, state.tau, F);
  engine.udot(state.t, state.q, state.u, state.tau, udot);
  require_finite(qdot, "qdot", model.q_names, model, state);
  require_finite(M, "M", {}, model, state);
  require_finite(F, "F", model.u_names, model, state);
  require_finite(udot, "udot", model.u_names, model, state);

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
  if (engine.has_locks()) {
    auto names = nlohmann::ordered_json::array();
    for (std::size_t b = 0; b < model.bodies.size(); ++b)
      if (state.locked[b]) names.push_back(model.bodies[b].name);
    j["locked"] = names;
  }
  if (model.outputs.energy) {
    const EnergyValues E = engine.energy(state.t, state.q, state.u);
    require_finite(Eigen::Vector2d(E.T, E.V), "energy (T, V)", {"T", "V"}, model, state);
    j["energy"] = {{"T", E.T}, {"V", E.V}};
  }
  if (model.outputs.momentum) {
    const MomentumValues P = engine.momentum(state.t, state.q, state.u);
    require_finite(P.p_N, "momentum p", {"x", "y", "z"}, model, state);
    require_finite(P.H_N, "momentum H", {"x", "y", "z"}, model, state);
    j["momentum"] = {{"p", vec(P.p_N)}, {"H", vec(P.H_N)}};
  }
  if (model.outputs.reactions) {
    std::vector<Reaction> R;
    engine.reactions(state.t, state.q, state.u, udot, R);
    for (std::size_t i = 0; i < R.size(); ++i) {
      require_finite(R[i].force_B, "reaction force on " + model.bodies[i].name, {"x", "y", "z"}, model, state);
      require_finite(R[i].torque_B, "reaction torque on " + model.bodies[i].name, {"x", "y", "z"}, model, state);
    }
    nlohmann::ordered_json jr;
    for (std::size_t i = 0; i < R.size(); ++i)
      jr[model.bodies[i].name] = {{"force", vec(R[i].force_B)}, {"torque", vec(R[i].torque_B)}};
    j["reactions"] = jr;
  }
  if (model.nw > 0) {
    nlohmann::ordered_json ji;
    for (int i = 0; i < model.nw; ++i) ji[model.input_names[i]] = state.w(i);
    j["inputs"] = ji;
  }
  if (model.ny > 0) {
    VecX y;
    engine.outputs(state.t, state.q, state.u, state.tau, y);
    require_finite(y, "outputs", model.output_names, model, state);
    nlohmann::ordered_json jy;
    for (int i = 0; i < model.ny; ++i) jy[model.output_names[i]] = y(i);
    j["outputs"] = jy;
  }
  return j;
}

}  // namespace kanegen
