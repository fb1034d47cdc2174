#include "engine/model_checks.hpp"

#include "engine/generic_engine.hpp"
#include "model/state_io.hpp"

namespace kanegen {

void check_mass_matrix_at_initial_state(const Model& model) {
  GenericEngine engine(model);
  MatX M;
  engine.mass_matrix(model.q0, M);
  Eigen::LLT<MatX> llt(model.nu);
  try {
    factorize_mass_matrix(M, llt);
  } catch (const SingularMassMatrix& e) {
    throw InputError(Diagnostic{model.source_path, 0, "bodies",
                                std::string(e.what()) +
                                    " at the initial state; expected every degree of freedom to move some mass "
                                    "(check massless bodies and zero inertias)"});
  }
}

}  // namespace kanegen
