#include "engine/model_checks.hpp"

#include <fmt/format.h>

#include <cmath>

#include "dynamics/central_gravity.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/workspace.hpp"
#include "engine/generic_engine.hpp"
#include "model/state_io.hpp"

namespace kanegen {

namespace {

/// The first speed whose pivot fails in a Cholesky factorization of M in
/// speed order (relative to M's largest diagonal entry), or -1.
int first_singular_speed(const MatX& M) {
  const int n = static_cast<int>(M.rows());
  const double scale = n ? M.diagonal().cwiseAbs().maxCoeff() : 0.0;
  MatX L = MatX::Zero(n, n);
  for (int j = 0; j < n; ++j) {
    double d = M(j, j) - L.row(j).head(j).squaredNorm();
    if (!(d > 1e-14 * scale)) return j;
    L(j, j) = std::sqrt(d);
    for (int i = j + 1; i < n; ++i) L(i, j) = (M(i, j) - L.row(i).head(j).dot(L.row(j).head(j))) / L(j, j);
  }
  return -1;
}

}  // namespace

int gimbal_locked_body(const Model& model, const double* q, double limit, double* measure) {
  for (const int i : model.lockable_joints) {
    const Body& b = model.bodies[i];
    const double m = joint_lock_measure(b.joint, q + b.q_joint);
    if (!(m > limit)) {
      if (measure) *measure = m;
      return i;
    }
  }
  return -1;
}

std::string gimbal_lock_message(const Model& model, int body, const double* q, double measure) {
  const Body& b = model.bodies[body];
  std::string angles;
  for (int k = 0; k < joint_nq(b.joint); ++k)
    angles += fmt::format("{}{} = {:.17g}", k ? ", " : "", model.q_names[b.q_joint + k], q[b.q_joint + k]);
  return fmt::format("the {} joint of '{}' is in gimbal lock (|det Gamma| = {:.3g}: its rotation axes are linearly "
                     "dependent) at {}",
                     to_string(b.joint.type), b.name, measure, angles);
}

void check_mass_elements_off_the_centre(const Model& model) {
  if (!model.central) return;
  Workspace<double> ws(model);
  compute_kinematics(model, ws, 0.0, model.q0, model.u0);
  std::vector<Diagnostic> faults;
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const Body& b = model.bodies[i];
    BodyWorkspace<double>& s = ws.body[i];
    int element = 0;  // 0: the rigid part (or node 1 of a flexible body without one), then the nodes
    bool reported = false;
    for_each_mass_element(b, s, [&](double mass, const Vec3& s_B, const auto*, const Mat3&, const auto*, bool) {
      const Vec3 r = s.r_NO_N + s.R_NB * s_B;
      const double r2 = r.squaredNorm(), r5 = r2 * r2 * std::sqrt(r2);
      // the field (mu m / r^2) and its gradient (mu / r^5 with the inertia) must be numbers
      if (!reported && !(std::isfinite(model.central->mu * (mass > 0 ? mass : 1.0) / r2) &&
                         std::isfinite(model.central->mu / r5))) {
        const bool rigid = element == 0 && (b.rigid.mass != 0.0 || !b.rigid.I_c_B.isZero(0.0));
        faults.push_back(Diagnostic{
            model.source_path, b.line, fmt::format("bodies[{}]", i),
            fmt::format("{} of '{}' is at the attracting centre (|r| = {:.3g} m from N's origin at the initial state), "
                        "where the central field is singular; expected every mass element away from N's origin "
                        "(an initial: orbit:, or the root's position)",
                        rigid ? "the centre of mass" : "a node", b.name, std::sqrt(r2))});
        reported = true;
      }
      ++element;
    });
  }
  if (!faults.empty()) throw InputError(std::move(faults));
}

void check_mass_matrix_at_initial_state(const Model& model) {
  check_mass_elements_off_the_centre(model);
  double measure = 0;
  if (const int lb = gimbal_locked_body(model, model.q0.data(), kGimbalLockRefuse, &measure); lb >= 0)
    throw InputError(Diagnostic{model.source_path, model.bodies[lb].line, fmt::format("bodies[{}].joint", lb),
                                gimbal_lock_message(model, lb, model.q0.data(), measure) +
                                    " in the initial state; expected initial angles away from gimbal lock (or a ball "
                                    "joint, which has none)"});
  GenericEngine engine(model);
  MatX M;
  engine.mass_matrix(model.q0, M);
  Eigen::LLT<MatX> llt(model.nu);
  try {
    factorize_mass_matrix(M, llt);
  } catch (const SingularMassMatrix& e) {
    // Name the speed, its body (with the body's line) and the bodies it moves.
    const int k = first_singular_speed(M);
    int body = -1;
    for (std::size_t i = 0; i < model.bodies.size() && k >= 0; ++i) {
      const Body& b = model.bodies[i];
      if (k >= b.u_joint && k < b.u_joint + joint_nu(b.joint) + b.n_modes()) body = static_cast<int>(i);
    }
    if (body < 0)
      throw InputError(Diagnostic{model.source_path, 0, "bodies",
                                  std::string(e.what()) +
                                      " at the initial state; expected every degree of freedom to move some mass "
                                      "(check massless bodies and zero inertias)"});
    const Body& b = model.bodies[body];
    std::vector<std::string> moved{b.name};
    for (std::size_t i = body + 1; i < model.bodies.size(); ++i)
      for (int p = model.bodies[i].parent; p >= 0; p = model.bodies[p].parent)
        if (p == body) {
          moved.push_back(model.bodies[i].name);
          break;
        }
    std::string list;
    for (std::size_t i = 0; i < moved.size() && i < 8; ++i) list += (i ? ", " : "") + moved[i];
    if (moved.size() > 8) list += fmt::format(" and {} more", moved.size() - 8);
    throw InputError(Diagnostic{
        model.source_path, b.line, fmt::format("bodies[{}] ({})", body, b.name),
        fmt::format("the mass matrix is singular at the initial state: speed '{}' moves no mass or inertia that the "
                    "other speeds do not already move (it moves {}); expected every degree of freedom to move some "
                    "mass: give these bodies mass or inertia about the joint axis, or make the joint fixed",
                    model.u_names[k], list)});
  }
}

}  // namespace kanegen
