#include "engine/generated_engine.hpp"

#include <fmt/format.h>

#include <cstring>

#include "model/model_hash.hpp"
#include "model/parameters.hpp"

namespace kanegen {

namespace {
std::string str_or(const char* s) { return s ? std::string(s) : std::string("(null)"); }

KanegenArgs args(double t, const VecX* q, const VecX* u, const VecX* tau, const VecX* udot, const VecX& w,
                 const VecX& p) {
  KanegenArgs a{};
  a.inputs = w.data();
  a.params = p.data();
  a.t = t;
  a.q = q ? q->data() : nullptr;
  a.u = u ? u->data() : nullptr;
  a.tau = tau ? tau->data() : nullptr;
  a.udot = udot ? udot->data() : nullptr;
  return a;
}
}  // namespace

GeneratedEngine::GeneratedEngine(const Model& m, const KanegenGeneratedApi* api, std::shared_ptr<void> library,
                                 const std::string& expected_generator_hash, std::vector<RuntimeParameter> implicit)
    : Engine(m), api_(api), library_(std::move(library)) {
  if (!api_) throw std::runtime_error("generated code: no API table (its kanegen_api_<model>() returned NULL)");
  const std::string who = fmt::format("generated code for model '{}'", str_or(api_->model_name));
  if (api_->api_version != KANEGEN_GENERATED_API_VERSION)
    throw std::runtime_error(fmt::format("{}: API version {} but this runtime expects {}; regenerate it", who,
                                         api_->api_version, KANEGEN_GENERATED_API_VERSION));
  if (api_->nq != m.nq || api_->nu != m.nu || api_->nbodies != static_cast<int>(m.bodies.size()) ||
      api_->nw != m.nw || api_->ny != m.ny || api_->np != static_cast<int>(m.parameters.size() + implicit.size()))
    throw std::runtime_error(fmt::format("{}: nq = {}, nu = {}, {} bodies, but the model '{}' has nq = {}, nu = {}, "
                                         "{} bodies; regenerate it",
                                         who, api_->nq, api_->nu, api_->nbodies, m.source_path, m.nq, m.nu,
                                         m.bodies.size()));
  const std::string hash = model_hash(implicit.empty() ? m : with_parameters(m, implicit));
  if (str_or(api_->model_hash) != hash)
    throw std::runtime_error(fmt::format("{} was generated from a different version of the model (hash {}, the model "
                                         "'{}' has {}); regenerate it",
                                         who, str_or(api_->model_hash), m.source_path, hash));
  if (!expected_generator_hash.empty() && str_or(api_->generator_hash) != expected_generator_hash)
    throw std::runtime_error(fmt::format("{} was written by another generator (hash {}, this one is {}); regenerate it",
                                         who, str_or(api_->generator_hash), expected_generator_hash));
  qdot_ = function("qdot");
  mass_matrix_ = function("mass_matrix");
  forcing_ = function("forcing");
  udot_ = function("udot");
  jacobian_ = function("jacobian");
  energy_ = function("energy");
  momentum_ = function("momentum");
  reactions_ = function("reactions");
  outputs_ = function("outputs");
  input_jacobian_ = function("input_jacobian");
  output_jacobian_ = function("output_jacobian");
  if (!qdot_ || !mass_matrix_ || !forcing_ || !udot_)
    throw std::runtime_error(fmt::format("{}: the table lacks one of qdot, mass_matrix, forcing, udot", who));
  M_row_major_.resize(m.nu, m.nu);
  code_parameters_.resize(static_cast<Eigen::Index>(m.parameters.size() + implicit.size()));
  for (std::size_t k = 0; k < implicit.size(); ++k)
    code_parameters_(static_cast<Eigen::Index>(m.parameters.size() + k)) = parameter_value(m, implicit[k]);
  parameters_changed();
}

void GeneratedEngine::parameters_changed() { code_parameters_.head(parameters().size()) = parameters(); }

KanegenFunctionPtr find_function(const KanegenGeneratedApi& api, const std::string& name) {
  for (int i = 0; i < api.n_functions; ++i)
    if (api.functions[i].name && name == api.functions[i].name) return api.functions[i].fn;
  return nullptr;
}

KanegenFunctionPtr GeneratedEngine::function(const std::string& name) const { return find_function(*api_, name); }

void GeneratedEngine::missing_output(const char* what) const {
  throw std::runtime_error(fmt::format("model was generated without '{}' output (add it to `outputs:` in {})", what,
                                       model().source_path.empty() ? model().name : model().source_path));
}

void GeneratedEngine::singular(int pivot) const {
  const std::string& name = pivot >= 1 && pivot <= model().nu ? model().u_names[pivot - 1] : std::string("?");
  throw SingularMassMatrix(
      fmt::format("mass matrix is singular (non-positive pivot of speed '{}' in the factorization)", name), pivot - 1);
}

void GeneratedEngine::do_qdot(const VecX& q, const VecX& u, VecX& qd) {
  const KanegenArgs a = args(0.0, &q, &u, nullptr, nullptr, inputs(), code_parameters_);
  qdot_(&a, qd.data());
}

void GeneratedEngine::do_mass_matrix(double t, const VecX& q, MatX& M) {
  // The table writes row-major; M is symmetric, but do not rely on it.
  const KanegenArgs a = args(t, &q, nullptr, nullptr, nullptr, inputs(), code_parameters_);
  mass_matrix_(&a, M_row_major_.data());
  M = M_row_major_.transpose();
}

void GeneratedEngine::do_forcing(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& F) {
  const KanegenArgs a = args(t, &q, &u, &tau, nullptr, inputs(), code_parameters_);
  forcing_(&a, F.data());
}

void GeneratedEngine::use_udot(KanegenFunctionPtr fn, std::shared_ptr<void> library, std::string compiler) {
  if (!fn) throw std::logic_error("GeneratedEngine::use_udot: no function");
  udot_ = fn;
  udot_library_ = std::move(library);
  udot_compiler_ = std::move(compiler);
}

int GeneratedEngine::call_udot(KanegenFunctionPtr fn, double t, const VecX& q, const VecX& u, const VecX& tau,
                               double* out) const {
  const KanegenArgs a = args(t, &q, &u, &tau, nullptr, inputs(), code_parameters_);
  return fn(&a, out);
}

void GeneratedEngine::do_udot(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& ud) {
  const KanegenArgs a = args(t, &q, &u, &tau, nullptr, inputs(), code_parameters_);
  if (const int pivot = udot_(&a, ud.data()); pivot != 0) singular(pivot);
}

bool GeneratedEngine::do_jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& J) {
  if (!jacobian_) return false;
  const KanegenArgs a = args(t, &q, &u, &tau, nullptr, inputs(), code_parameters_);
  if (const int pivot = jacobian_(&a, J.data()); pivot != 0) singular(pivot);
  return true;
}

EnergyValues GeneratedEngine::do_energy(double t, const VecX& q, const VecX& u) {
  if (!energy_) missing_output("energy");
  double TV[2] = {0, 0};
  const KanegenArgs a = args(t, &q, &u, nullptr, nullptr, inputs(), code_parameters_);
  energy_(&a, TV);
  return {TV[0], TV[1]};
}

MomentumValues GeneratedEngine::do_momentum(double t, const VecX& q, const VecX& u) {
  if (!momentum_) missing_output("momentum");
  double pH[6] = {0, 0, 0, 0, 0, 0};
  const KanegenArgs a = args(t, &q, &u, nullptr, nullptr, inputs(), code_parameters_);
  momentum_(&a, pH);
  MomentumValues r;
  r.p_N = Vec3(pH[0], pH[1], pH[2]);
  r.H_N = Vec3(pH[3], pH[4], pH[5]);
  return r;
}

void GeneratedEngine::do_reactions(double t, const VecX& q, const VecX& u, const VecX& ud,
                                   std::vector<Reaction>& out) {
  if (!reactions_) missing_output("reactions");
  const std::size_t nb = model().bodies.size();
  wrenches_.assign(6 * nb, 0.0);
  const KanegenArgs a = args(t, &q, &u, nullptr, &ud, inputs(), code_parameters_);
  reactions_(&a, wrenches_.data());
  for (std::size_t i = 0; i < nb; ++i) {
    const double* w = &wrenches_[6 * i];
    out[i].force_B = Vec3(w[0], w[1], w[2]);
    out[i].torque_B = Vec3(w[3], w[4], w[5]);
  }
}

void GeneratedEngine::do_outputs(double t, const VecX& q, const VecX& u, const VecX& tau, VecX& y) {
  if (model().ny == 0) return;
  if (!outputs_) missing_output("outputs (named sensors)");
  const KanegenArgs a = args(t, &q, &u, &tau, nullptr, inputs(), code_parameters_);
  outputs_(&a, y.data());
}

bool GeneratedEngine::do_input_jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& B) {
  if (model().nw == 0) return true;
  if (!input_jacobian_) return false;
  const KanegenArgs a = args(t, &q, &u, &tau, nullptr, inputs(), code_parameters_);
  if (const int pivot = input_jacobian_(&a, B.data()); pivot != 0) singular(pivot);
  return true;
}

bool GeneratedEngine::do_output_jacobian(double t, const VecX& q, const VecX& u, const VecX& tau, MatX& CD) {
  if (model().ny == 0) return true;
  if (!output_jacobian_) return false;
  const KanegenArgs a = args(t, &q, &u, &tau, nullptr, inputs(), code_parameters_);
  output_jacobian_(&a, CD.data());
  return true;
}

}  // namespace kanegen
