#include "sim/linearize.hpp"

#include "engine/locks.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <optional>

#include "model/diagnostics.hpp"
#include "sim/dual_number.hpp"
#include "sim/orbit_relative_state.hpp"

namespace kanegen {

namespace {

constexpr double kTwoPi = 6.283185307179586476925;
/// |f(x0)| at most this (SI units) counts as an equilibrium.
constexpr double kEquilibriumTolerance = 1e-9;

/// An input column: a named input's entry or a generalized force.
struct InputColumn {
  std::string name;
  int w = -1;    ///< entry of w, or -1
  int tau = -1;  ///< entry of tau, or -1
};

std::vector<InputColumn> input_columns(const Model& model, const std::vector<std::string>& wanted) {
  std::vector<InputColumn> cols;
  if (wanted.empty()) {
    if (model.nw > 0)
      for (int i = 0; i < model.nw; ++i) cols.push_back({model.input_names[i], i, -1});
    else
      for (int i = 0; i < model.nu; ++i) cols.push_back({"tau." + model.u_names[i], -1, i});
    return cols;
  }
  for (const std::string& n : wanted) {
    if (const int i = model.input_index(n); i >= 0) {
      cols.push_back({n, i, -1});
      continue;
    }
    if (n.rfind("tau.", 0) == 0)
      if (const int i = model.speed_index(n.substr(4)); i >= 0) {  // the older speed names too
        cols.push_back({"tau." + model.u_names[i], -1, i});
        continue;
      }
    // a vector input by its name: all three entries
    bool found = false;
    for (int i = 0; i < model.nw; ++i)
      if (model.input_names[i].rfind(n + ".", 0) == 0) {
        cols.push_back({model.input_names[i], i, -1});
        found = true;
      }
    if (!found)
      throw InputError(Diagnostic{"(command line)", 0, "--inputs",
                                  fmt::format("unknown input '{}'; expected a named input ({}) or tau.<speed>", n,
                                              model.input_names.empty() ? std::string("the model declares none")
                                                                        : fmt::format("{}", fmt::join(model.input_names, ", ")))});
  }
  return cols;
}

std::vector<int> output_rows(const Model& model, const std::vector<std::string>& wanted) {
  std::vector<int> rows;
  if (wanted.empty()) {
    rows.resize(model.ny);
    std::iota(rows.begin(), rows.end(), 0);
    return rows;
  }
  for (const std::string& n : wanted) {
    if (const int i = model.output_index(n); i >= 0) {
      rows.push_back(i);
      continue;
    }
    bool found = false;
    for (const Sensor& s : model.sensors)
      if (s.name == n) {
        for (int k = 0; k < s.size(); ++k) rows.push_back(s.offset + k);
        found = true;
      }
    if (!found)
      throw InputError(Diagnostic{"(command line)", 0, "--outputs",
                                  fmt::format("unknown output '{}'; expected a sensor or an entry of one ({})", n,
                                              model.output_names.empty() ? std::string("the model declares none")
                                                                         : fmt::format("{}", fmt::join(model.output_names, ", ")))});
  }
  return rows;
}

/// The sensor an output entry belongs to.
const Sensor& sensor_of(const Model& model, int row) {
  for (const Sensor& s : model.sensors)
    if (row >= s.offset && row < s.offset + s.size()) return s;
  throw std::logic_error("output row without a sensor");
}

/// x_dot = [q_dot; u_dot] at (q, u) with the engine's current inputs.
VecX state_derivative(Engine& e, double t, const VecX& q, const VecX& u, const VecX& tau) {
  VecX qd, ud;
  e.qdot(q, u, qd);
  e.udot(t, q, u, tau, ud);
  VecX x(qd.size() + ud.size());
  x << qd, ud;
  return x;
}

/// J = d[q_dot; u_dot]/d[q; u], Bw = d(u_dot)/dw and CD = dy/d[q; u; w; tau], exact (dual numbers through the
/// generated code); false when the engine has no such derivatives. With joints locked they are the reduced
/// system's (dynamics.md, Locks): its u_dot is the free system's g(x, tau0 + E_l lambda(x)) with the locking
/// force lambda that holds u_dot_l = 0, so d(u_dot) = P dg, P = I - M^-1 E_l S^-1 E_l', S = E_l' M^-1 E_l, with
/// dg taken at tau* = tau0 + E_l lambda0 (where g equals the reduced u_dot) and u_l = 0 (the reduced system's
/// speeds). The outputs under locks are the free system's at tau* too (Engine::outputs), so CD is the free
/// system's plus the locking torque's share: dy = CD_free + CD_tau E dlambda, dlambda = -S^-1 E' dg over every
/// column (q, u, w, tau). false too when the free system's M (`M`, at q0) is singular while the reduced one's
/// is not (a massless body on a locked joint): central differences of the reduced u_dot then.
bool exact_derivatives(Engine& engine, double t, const VecX& q0, const VecX& u0, const VecX& tau0, const MatX& M,
                       MatX& J, MatX& Bw, MatX& CD) {
  if (!engine.has_locks())
    return engine.jacobian(t, q0, u0, tau0, J) && engine.input_jacobian(t, q0, u0, tau0, Bw) &&
           engine.output_jacobian(t, q0, u0, tau0, CD);
  const std::vector<int> locked = engine.locked_u();  // a copy: the free system's scope below clears them
  const int nu = static_cast<int>(u0.size()), nl = static_cast<int>(locked.size());
  VecX u = u0;
  for (const int k : locked) u(k) = 0.0;
  const VecX tau_star = engine.locked_tau(t, q0, u, tau0);
  const Eigen::LLT<MatX> M_llt(M);
  if (M_llt.info() != Eigen::Success) return false;
  try {
    const ScopedLocks free_system(engine, LockSet{});
    if (!engine.jacobian(t, q0, u, tau_star, J) || !engine.input_jacobian(t, q0, u, tau_star, Bw) ||
        !engine.output_jacobian(t, q0, u, tau_star, CD))
      return false;
  } catch (const SingularMassMatrix&) {
    return false;
  }
  MatX E_l = MatX::Zero(nu, nl);
  for (int c = 0; c < nl; ++c) E_l(locked[c], c) = 1.0;
  const MatX Minv_El = M_llt.solve(E_l);
  const Eigen::LDLT<MatX> S(E_l.transpose() * Minv_El);
  if (CD.rows() > 0) {
    // dg over CD's columns [q; u; w; tau], the locked rows: J's, Bw's and M^-1's (= (M^-1 E)')
    const int nx = static_cast<int>(J.cols()), nw = static_cast<int>(Bw.cols());
    MatX G_l(nl, CD.cols());
    for (int r = 0; r < nl; ++r) {
      G_l.block(r, 0, 1, nx) = J.row(J.rows() - nu + locked[r]);
      G_l.block(r, nx, 1, nw) = Bw.row(locked[r]);
    }
    G_l.rightCols(nu) = Minv_El.transpose();
    MatX CD_tau_l(CD.rows(), nl);
    for (int c = 0; c < nl; ++c) CD_tau_l.col(c) = CD.col(nx + nw + locked[c]);
    CD -= CD_tau_l * S.solve(G_l);
  }
  const MatX P = MatX::Identity(nu, nu) - Minv_El * S.solve(E_l.transpose());
  J.bottomRows(nu) = P * J.bottomRows(nu).eval();
  Bw = P * Bw;
  return true;
}

}  // namespace

Eigen::Matrix<double, 4, 3> quaternion_xi(const Eigen::Vector4d& q) {
  Eigen::Matrix<double, 4, 3> X;
  const double w = q(0), x = q(1), y = q(2), z = q(3);
  X << -x, -y, -z,  //
      w, -z, y,     //
      z, w, -x,     //
      -y, x, w;
  return X;
}

namespace {

/// LinearModel::ignorable and the relative equilibrium, from A and x0_dot. `body_of`: per state its joint's body.
void find_ignorable(LinearModel& lin, const std::vector<int>& body_of) {
  const int n = static_cast<int>(lin.A.rows());
  // exact derivatives: zero is zero to rounding; central differences carry ~1e-8 of noise. Small against the
  // entry's own row: a yaw stiffness of n^2 (Iy - Ix)/Iz ~ 8e-7 1/s^2 is most of its row, though far below the
  // unit entries of the kinematic rows (a threshold on max |A| dropped a libration angle as ignorable)
  const bool exact = lin.method.rfind("exact", 0) == 0;
  // (a row of nothing but noise is judged against 1e-6 max |A| instead)
  const VecX row_scale = n ? VecX(lin.A.cwiseAbs().rowwise().maxCoeff()) : VecX();
  const double floor = 1e-6 * std::max(1.0, n ? lin.A.cwiseAbs().maxCoeff() : 0.0);
  auto small = [&](int r) { return (exact ? 1e-12 : 1e-6) * std::max(row_scale(r), floor); };
  auto is_q = [&](int i) { return lin.state_names[i].rfind("q.", 0) == 0; };
  // in the orbit frame the central field restores the cross-track and radial offsets (Clohessy-Wiltshire's
  // -n^2 y and 3 n^2 z): never ignorable, though by central differences their n^2 may sink below the noise
  // threshold of a fast-spinning body's A
  auto restored = [&](int i) {
    const std::string& s = lin.state_names[i];
    auto ends = [&](const std::string& tail) {
      return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
    };
    return lin.frame == "lvlh" && (ends(".lvlh.y") || ends(".lvlh.z"));
  };
  std::vector<bool> cand(n, false);
  for (int i = 0; i < n; ++i) cand[i] = is_q(i) && body_of[i] >= 0 && !restored(i);
  for (bool changed = true; changed;) {  // a candidate only other same-joint candidates depend on
    changed = false;
    for (int i = 0; i < n; ++i) {
      if (!cand[i]) continue;
      for (int j = 0; j < n; ++j)
        if (std::abs(lin.A(j, i)) > small(j) && !(cand[j] && body_of[j] == body_of[i])) {
          cand[i] = false, changed = true;
          break;
        }
    }
  }
  lin.ignorable.clear();
  double rest = 0, own = 0;
  for (int i = 0; i < n; ++i) {
    if (cand[i]) lin.ignorable.push_back(lin.state_names[i]);
    (cand[i] ? own : rest) = std::max(cand[i] ? own : rest, std::abs(lin.x0_dot(i)) / lin.residual_scale(i));
  }
  lin.relative_residual = rest;
  lin.relative_equilibrium = !lin.equilibrium && rest <= kEquilibriumTolerance && own > 0;
}

/// The model restricted to the states `keep` (indices, ascending); with state outputs, C = I on them.
void keep_states(LinearModel& lin, const std::vector<int>& keep) {
  const int nk = static_cast<int>(keep.size());
  const bool state_outputs = lin.output_names == lin.state_names;
  MatX A(nk, nk), B(nk, lin.B.cols()), C(lin.C.rows(), nk);
  VecX xd(nk), scale(nk);
  std::vector<std::string> names;
  for (int r = 0; r < nk; ++r) {
    for (int c = 0; c < nk; ++c) A(r, c) = lin.A(keep[r], keep[c]);
    B.row(r) = lin.B.row(keep[r]);
    xd(r) = lin.x0_dot(keep[r]);
    scale(r) = lin.residual_scale(keep[r]);
    names.push_back(lin.state_names[keep[r]]);
  }
  for (int c = 0; c < nk; ++c) C.col(c) = lin.C.col(keep[c]);
  if (state_outputs) {
    lin.C = MatX::Identity(nk, nk);
    lin.D = MatX::Zero(nk, lin.B.cols());
    lin.output_names = names;
    lin.y0 = VecX::Zero(nk);
  } else {
    lin.C = C;
  }
  MatX K(nk, nk);
  for (int r = 0; r < nk; ++r)
    for (int c = 0; c < nk; ++c) K(r, c) = lin.kinetic(keep[r], keep[c]);
  lin.A = A, lin.B = B, lin.x0_dot = xd, lin.residual_scale = scale, lin.state_names = names, lin.kinetic = K;
}

/// max |x0_dot| / residual_scale: what the equilibrium is judged on.
double scaled_residual(const LinearModel& lin) {
  return lin.x0_dot.size() ? lin.x0_dot.cwiseAbs().cwiseQuotient(lin.residual_scale).maxCoeff() : 0.0;
}

/// The model without the states named `drop` (none of the others depends on them).
void drop_states(LinearModel& lin, const std::vector<std::string>& drop) {
  std::vector<int> keep;
  for (int i = 0; i < static_cast<int>(lin.state_names.size()); ++i)
    if (std::find(drop.begin(), drop.end(), lin.state_names[i]) == drop.end()) keep.push_back(i);
  keep_states(lin, keep);
  lin.ignorable_dropped = true;
  // without the ignorable rows the point is an equilibrium of what is left when it was a relative one
  lin.residual = scaled_residual(lin);
  lin.equilibrium = lin.residual <= kEquilibriumTolerance;
}

/// Each entry of x = [q; u]'s scale for a difference step: max(1, the norm of the vector it belongs to): a free
/// joint's position, a quaternion, a free joint's velocity, a quaternion's angular velocity (so that a step
/// turning the orbit's 7.5e3 m/s by 1e-6 rad counts as 1e-6 of the velocity, not as 7.5e-3 of a zero entry);
/// max(1, |x_i|) for the others.
VecX entry_scales(const Model& model, const VecX& x) {
  VecX s = x.cwiseAbs().cwiseMax(1.0);
  auto group = [&](int from, int size) {
    s.segment(from, size).setConstant(std::max(1.0, x.segment(from, size).norm()));
  };
  for (const auto& slot : model.quaternions) {
    const bool free = model.bodies[slot.body].joint.type == JointType::free;
    group(slot.q, 4);
    group(model.nq + slot.u, 3);
    if (free) {  // q = [r, quaternion], u = [v, w]
      group(slot.q - 3, 3);
      group(model.nq + slot.u - 3, 3);
    }
  }
  return s;
}

/// The rate of the orbit frame's chart and the outputs at a full state x = [q; u]: g(x) = J_phi(x) x_dot(x) +
/// phi_t, y(x). Set for central differences only.
using ChartRates = std::function<void(const VecX& x, VecX& g, VecX& y)>;

/// g(x) = dz/dt along the flow: the chart through dual numbers carrying x_dot and dt = 1.
VecX chart_rate(const OrbitRelativeState& chart, const VecX& q, const VecX& u, const VecX& x_dot, double t) {
  using D1 = Dual<double>;
  const int nq = static_cast<int>(q.size()), nu = static_cast<int>(u.size());
  std::vector<D1> qq(nq), uu(nu), z(chart.size());
  for (int i = 0; i < nq; ++i) qq[i] = D1(q(i), x_dot(i));
  for (int k = 0; k < nu; ++k) uu[k] = D1(u(k), x_dot(nq + k));
  chart.apply(qq.data(), uu.data(), D1(t, 1.0), z.data());
  VecX g(chart.size());
  for (int r = 0; r < chart.size(); ++r) g(r) = z[r].d;
  return g;
}

/// The linear model in the orbit frame's chart z = phi(x, t) (sim/orbit_relative_state.hpp), from the
/// tangent one: with xi the tangent state (x = x0 + T_in xi + ...), P = dz/dxi = J_phi T_in and
/// z_dot = g(xi) = J_phi(x) x_dot(x) + phi_t,
///   dg/dxi = phi''[x_dot, T_in] + phi_t'[T_in] + J_phi J T_in,   A_z = dg/dxi P^-1,
/// the second derivatives exact by nested dual numbers (directions: the flow (x_dot, 1) and each column
/// of T_in); B_z = P B, C_z = C P^-1. J_phi is taken over the full coordinates (the chart's extension off
/// the unit quaternions included), since J's quaternion rows may leave the sphere.
/// With `rates` (central differences: g and the outputs y at a full state x), A_z and C_z are differenced in
/// the chart's own coordinates instead: column j along x0 +- h d_j, d_j = T_in P^-1 e_j (a unit step of z_j,
/// to first order), h such that no entry of x moves by more than 1e-5 of its scale (entry_scales; near the optimum
/// eps^(1/3) of central differences: the position rows subtract the orbit's 7.5e3 m/s, so their round-off is
/// eps 7.5e3 / h; 1.8e-7 against the exact A at 1e-5, 2.2e-6 at 1e-6). Differencing in x and
/// turning the result by P^-1 would multiply the differences' round-off by P^-1's orbital speed: an attitude
/// step at fixed body-axis velocity turns the orbit's 7.5e3 m/s, and P^-1 undoes that (A off by 2e-3 so).
void to_orbit_frame(LinearModel& lin, const OrbitRelativeState& chart, const Model& model, const State& state,
                    const MatX& J, const MatX& T_in, const VecX& x_dot, const MatX& R_y, const ChartRates& rates) {
  const int nq = model.nq, nu = model.nu, nx = nq + nu, n = chart.size();
  using D1 = Dual<double>;
  using D2 = Dual<D1>;
  MatX J_phi(n, nx);
  {
    std::vector<D1> q(nq), u(nu), z(n);
    const D1 t(state.t);
    for (int c = 0; c < nx; ++c) {
      for (int i = 0; i < nq; ++i) q[i] = D1(state.q(i), c == i ? 1.0 : 0.0);
      for (int k = 0; k < nu; ++k) u[k] = D1(state.u(k), c == nq + k ? 1.0 : 0.0);
      chart.apply(q.data(), u.data(), t, z.data());
      for (int r = 0; r < n; ++r) J_phi(r, c) = z[r].d;
    }
  }
  MatX G(n, n);
  VecX g0(n);
  {
    std::vector<D2> q(nq), u(nu), z(n);
    const D2 t(D1(state.t, 1.0), D1(0.0, 0.0));
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < nq; ++i) q[i] = D2(D1(state.q(i), x_dot(i)), D1(T_in(i, j), 0.0));
      for (int k = 0; k < nu; ++k) u[k] = D2(D1(state.u(k), x_dot(nq + k)), D1(T_in(nq + k, j), 0.0));
      chart.apply(q.data(), u.data(), t, z.data());
      for (int r = 0; r < n; ++r) G(r, j) = z[r].d.d;
      if (j == 0)
        for (int r = 0; r < n; ++r) g0(r) = z[r].v.d;
    }
  }
  const MatX P = J_phi * T_in;
  const Eigen::PartialPivLU<MatX> lu(P);
  const MatX P_inv = lu.inverse();
  MatX Y_z;  // dy/dz by differences
  if (rates) {
    const VecX x0 = (VecX(nx) << state.q, state.u).finished();
    const MatX D = T_in * P_inv;
    Y_z.resize(model.ny, n);
    VecX gp, gm, yp(model.ny), ym(model.ny);
    const VecX scale = entry_scales(model, x0);
    for (int j = 0; j < n; ++j) {
      const double reach = D.col(j).cwiseAbs().cwiseQuotient(scale).maxCoeff();
      const double h = 1e-5 / std::max(reach, 1e-300);
      rates(x0 + h * D.col(j), gp, yp);
      rates(x0 - h * D.col(j), gm, ym);
      G.col(j) = (gp - gm) / (2 * h);
      Y_z.col(j) = (yp - ym) / (2 * h);
    }
    lin.A = G;
  } else {
    G += J_phi * (J * T_in);
    lin.A = G * P_inv;
  }
  lin.B = P * lin.B;
  {  // the kinetic energy of the motion relative to the orbit frame: M on the chart's speeds at fixed
     // coordinates (carrying M through the whole of P^-1 would count the orbit's 7e3 m/s turned by an attitude
     // perturbation as the mode's energy)
    const int nu = model.nu;
    const MatX S = P_inv.bottomRightCorner(nu, nu);
    const MatX M_u = lin.kinetic.bottomRightCorner(nu, nu);
    lin.kinetic.setZero();
    lin.kinetic.bottomRightCorner(nu, nu) = S.transpose() * M_u * S;
  }
  const bool state_outputs = lin.output_names == lin.state_names;
  lin.state_names = chart.names();
  if (state_outputs) {
    lin.output_names = lin.state_names;
  } else {
    lin.C = rates ? MatX(R_y * Y_z) : MatX(lin.C * P_inv);
  }
  lin.x0_dot = g0;
  // the orbit's own scale for the root's translation rows
  const double speed = std::max(1.0, chart.orbit_rate() * chart.com_position().norm());
  const double accel = std::max(1.0, chart.orbit_rate() * speed);
  const std::string& root = model.bodies[chart.root()].name;
  for (int r = 0; r < n; ++r) {
    const std::string& name = lin.state_names[r];
    for (const char* a : {".lvlh.x", ".lvlh.y", ".lvlh.z"})
      if (name == "q." + root + a) lin.residual_scale(r) = speed;
    for (const char* a : {".lvlh.vx", ".lvlh.vy", ".lvlh.vz"})
      if (name == "u." + root + a) lin.residual_scale(r) = accel;
  }
  lin.frame = "lvlh";
}

}  // namespace

LinearModel linearize(Engine& engine, const State& state, const LinearizeOptions& options) {
  const Model& model = engine.model();
  const int nq = model.nq, nu = model.nu, nx = nq + nu;
  const std::vector<InputColumn> in_cols = input_columns(model, options.inputs);
  const bool state_outputs = model.ny == 0 && options.outputs.empty();
  const std::vector<int> out_rows = state_outputs ? std::vector<int>{} : output_rows(model, options.outputs);
  // the frame, and in the orbit frame its chart (which refuses a model without a central field or a free root),
  // before any derivative is taken
  if (options.frame != "inertial" && options.frame != "lvlh")
    throw InputError(Diagnostic{"(command line)", 0, "--frame",
                                fmt::format("unknown frame '{}'; expected inertial or lvlh", options.frame)});
  const std::optional<OrbitRelativeState> orbit_chart =
      options.frame == "lvlh" ? std::optional<OrbitRelativeState>(std::in_place, model, state) : std::nullopt;
  engine.set_inputs(state.w);
  // With joints locked (State::locked) the linear model is the reduced
  // system's: the locked joints' coordinates and speeds are no states.
  const ScopedLocks locks(engine, state.locked);
  const double t = state.t;
  const VecX &q0 = state.q, &u0 = state.u, &tau0 = state.tau;

  // ---- full-coordinate derivatives: J = d[q_dot; u_dot]/d[q; u], Bw, Btau, CD
  MatX J(nx, nx), Bw(nu, model.nw), Btau(nu, nu), CD(model.ny, nq + 2 * nu + model.nw);
  MatX M;
  engine.mass_matrix(t, q0, M);
  const bool exact = !options.finite_differences && engine.has_jacobian() &&
                     exact_derivatives(engine, t, q0, u0, tau0, M, J, Bw, CD);
  // d(u_dot)/d(tau) = M^-1, exactly (u_dot is linear in tau).
  if (engine.has_locks()) {  // the reduced system's: M_ff^-1 on the free speeds
    VecX col;
    for (int k = 0; k < nu; ++k) {
      reduced_udot(M, VecX::Unit(nu, k), engine.locked_u(), col);
      Btau.col(k) = col;
    }
  } else {
    Btau = M.llt().solve(MatX::Identity(nu, nu));
  }
  VecX y0 = VecX::Zero(model.ny);
  if (model.ny > 0) engine.outputs(t, q0, u0, tau0, y0);
  if (!exact) {
    // central differences, step scaled to each variable
    const VecX w0 = state.w;
    VecX x0(nx);
    x0 << q0, u0;
    auto step = [](double v) { return 1e-6 * std::max(1.0, std::abs(v)); };
    // in the orbit frame A and C are differenced in the chart's own coordinates (to_orbit_frame): only the
    // input columns are needed here
    const int first = orbit_chart ? nx : 0;
    if (orbit_chart) J.setZero(), CD.leftCols(nx).setZero();
    for (int c = first; c < nq + 2 * nu + model.nw; ++c) {
      VecX q = q0, u = u0, tau = tau0, w = w0;
      double* v = c < nq ? &q(c) : c < nx ? &u(c - nq) : c < nx + model.nw ? &w(c - nx) : &tau(c - nx - model.nw);
      const double v0 = *v, h = step(v0);
      VecX fp, fm, yp(model.ny), ym(model.ny);
      *v = v0 + h;
      engine.set_inputs(w);
      fp = state_derivative(engine, t, q, u, tau);
      if (model.ny) engine.outputs(t, q, u, tau, yp);
      *v = v0 - h;
      engine.set_inputs(w);
      fm = state_derivative(engine, t, q, u, tau);
      if (model.ny) engine.outputs(t, q, u, tau, ym);
      const VecX df = (fp - fm) / (2 * h);
      if (c < nx) J.col(c) = df;
      else if (c < nx + model.nw) Bw.col(c - nx) = df.tail(nu);
      if (model.ny) CD.col(c) = (yp - ym) / (2 * h);
    }
    engine.set_inputs(w0);
  }

  // ---- the tangent space: T_in (nx x n), T_out (n x nx)
  const int nfree = static_cast<int>(model.quaternions.size());  // one tangent row fewer per quaternion
  const int nqt = nq - nfree, n = nqt + nu;
  MatX T_in = MatX::Zero(nx, n), T_out = MatX::Zero(n, nx);
  LinearModel lin;
  std::vector<int> state_body;  // per tangent state: the body whose joint it belongs to (-1: a mode)
  {
    std::vector<bool> quat_row(nq, false);
    std::vector<std::string> qt_names;
    int r = 0;  // tangent row
    for (int i = 0; i < nq;) {
      const Body* free_body = nullptr;
      for (const auto& slot : model.quaternions)
        if (slot.q == i) free_body = &model.bodies[slot.body];
      if (free_body) {
        const Eigen::Vector4d qq = q0.segment<4>(i).normalized();
        const Eigen::Matrix<double, 4, 3> Xi = quaternion_xi(qq);
        T_in.block(i, r, 4, 3) = 0.5 * Xi;
        T_out.block(r, i, 3, 4) = 2.0 * Xi.transpose();
        for (const char* a : {".rx", ".ry", ".rz"}) lin.state_names.push_back("q." + free_body->name + a);
        for (int k = 0; k < 3; ++k) state_body.push_back(joint_body_of_coordinate(model, i));
        i += 4, r += 3;
      } else {
        T_in(i, r) = 1.0;
        T_out(r, i) = 1.0;
        lin.state_names.push_back("q." + model.q_names[i]);
        state_body.push_back(joint_body_of_coordinate(model, i));
        ++i, ++r;
      }
    }
    for (int k = 0; k < nu; ++k) {
      T_in(nq + k, nqt + k) = 1.0;
      T_out(nqt + k, nq + k) = 1.0;
      lin.state_names.push_back("u." + model.u_names[k]);
      state_body.push_back(joint_body_of_speed(model, k));
    }
  }
  lin.A = T_out * J * T_in;
  const int m = static_cast<int>(in_cols.size());
  lin.B = MatX::Zero(n, m);
  for (int k = 0; k < m; ++k) {
    lin.input_names.push_back(in_cols[k].name);
    lin.B.col(k).tail(nu) = in_cols[k].w >= 0 ? VecX(Bw.col(in_cols[k].w)) : VecX(Btau.col(in_cols[k].tau));
  }
  const VecX x_dot = state_derivative(engine, t, q0, u0, tau0);
  lin.x0_dot = T_out * x_dot;
  lin.residual_scale = VecX::Ones(n);
  lin.kinetic = MatX::Zero(n, n);
  lin.kinetic.bottomRightCorner(nu, nu) = M;

  MatX R_y;  // the output rows' map from the sensors' entries (none with state outputs)
  if (state_outputs) {
    lin.C = MatX::Identity(n, n);
    lin.D = MatX::Zero(n, m);
    lin.output_names = lin.state_names;
    lin.y0 = VecX::Zero(n);
  } else {
    // output rows as combinations of the sensors' entries, Y = R_y y: entries as they are, attitude
    // quaternions turned into small rotations of the output frame
    std::vector<std::pair<Eigen::RowVectorXd, double>> rows;  // R_y's row, y0's
    for (std::size_t k = 0; k < out_rows.size();) {
      const int row = out_rows[k];
      const Sensor& s = sensor_of(model, row);
      const bool whole_quaternion = s.type == SensorType::attitude && row == s.offset && k + 3 < out_rows.size() &&
                                    out_rows[k + 3] == s.offset + 3;
      if (whole_quaternion) {
        const Eigen::Matrix<double, 3, 4> P = 2.0 * quaternion_xi(y0.segment<4>(s.offset)).transpose();
        for (int a = 0; a < 3; ++a) {
          Eigen::RowVectorXd r = Eigen::RowVectorXd::Zero(model.ny);
          r.segment<4>(s.offset) = P.row(a);
          rows.push_back({r, 0.0});
        }
        for (const char* a : {".rx", ".ry", ".rz"}) lin.output_names.push_back(s.name + a);
        k += 4;
      } else {
        if (s.type == SensorType::attitude)
          throw InputError(Diagnostic{"(command line)", 0, "--outputs",
                                      fmt::format("'{}': an attitude output is linearized as a whole (a small "
                                                  "rotation); expected '{}'",
                                                  model.output_names[row], s.name)});
        rows.push_back({Eigen::RowVectorXd::Unit(model.ny, row), y0(row)});
        lin.output_names.push_back(model.output_names[row]);
        ++k;
      }
    }
    const int p = static_cast<int>(rows.size());
    R_y.resize(p, model.ny);
    lin.y0.resize(p);
    for (int r = 0; r < p; ++r) R_y.row(r) = rows[r].first, lin.y0(r) = rows[r].second;
    const MatX CD_y = R_y * CD;
    lin.C = CD_y.leftCols(nx) * T_in;
    lin.D.resize(p, m);
    for (int c = 0; c < m; ++c)
      lin.D.col(c) = in_cols[c].w >= 0 ? VecX(CD_y.col(nx + in_cols[c].w)) : VecX(CD_y.col(nx + model.nw + in_cols[c].tau));
  }
  lin.method = exact ? "exact: forward-mode dual numbers through the generated code"
                     : "central differences (step 1e-6 max(1, |x|)) of the " + engine.name() + " engine";
  if (orbit_chart) {
    ChartRates rates;
    if (!exact)
      rates = [&](const VecX& x, VecX& g, VecX& y) {
        const VecX q = x.head(nq), u = x.tail(nu);
        g = chart_rate(*orbit_chart, q, u, state_derivative(engine, t, q, u, tau0), t);
        if (model.ny) engine.outputs(t, q, u, tau0, y);
      };
    to_orbit_frame(lin, *orbit_chart, model, state, J, T_in, x_dot, R_y, rates);
    lin.method = exact ? lin.method + "; the orbit frame's chart exact (nested dual numbers)"
                       : "central differences in the orbit frame's chart (each relative coordinate stepped, no entry "
                         "of the state moved by more than 1e-5 of its vector's max(1, |v|)) of the " + engine.name() +
                             " engine";
  }
  lin.residual = scaled_residual(lin);
  lin.equilibrium = lin.residual <= kEquilibriumTolerance;
  if (engine.has_locks()) {  // the reduced system: drop the locked joints' states
    std::vector<int> keep;
    for (int i = 0; i < n; ++i)
      if (state_body[i] < 0 || !state.locked[state_body[i]]) keep.push_back(i);
    std::vector<int> kept_body;
    for (int k : keep) kept_body.push_back(state_body[k]);
    state_body = kept_body;
    keep_states(lin, keep);
    lin.method += fmt::format(", reduced: {} locked joint speeds", engine.locked_u().size());
  }
  find_ignorable(lin, state_body);
  if (options.drop_ignorable && !lin.ignorable.empty()) {
    // an ignorable state a sensor reads (a position sensor on a free bus) stays: dropping it would change C
    std::vector<std::string> drop;
    const bool state_outputs = lin.output_names == lin.state_names;
    for (const std::string& name : lin.ignorable) {
      const auto i = std::find(lin.state_names.begin(), lin.state_names.end(), name) - lin.state_names.begin();
      if (state_outputs || lin.C.rows() == 0 || lin.C.col(i).cwiseAbs().maxCoeff() == 0.0) drop.push_back(name);
      else lin.ignorable_kept_for_outputs.push_back(name);
    }
    drop_states(lin, drop);
  }
  return lin;
}

double zero_mode_tolerance(const LinearModel& lin) {
  // a zero eigenvalue in a Jordan block (a free body's position and speed) comes out of the eigensolver
  // as +-sqrt(eps |A|): the tolerance scales with sqrt(|A|)
  return 1e-6 * std::sqrt(std::max(1.0, lin.A.size() ? lin.A.cwiseAbs().maxCoeff() : 0.0));
}

std::vector<LinearMode> linear_modes(const LinearModel& lin) {
  std::vector<LinearMode> out;
  const int n = static_cast<int>(lin.A.rows());
  if (n == 0) return out;
  Eigen::EigenSolver<MatX> es(lin.A, true);
  const auto& lam = es.eigenvalues();
  const auto& V = es.eigenvectors();
  int nqt = 0;
  for (const auto& s : lin.state_names) nqt += s.rfind("q.", 0) == 0 ? 1 : 0;
  const double zero_tol = zero_mode_tolerance(lin);
  for (int k = 0; k < n; ++k) {
    const std::complex<double> l = lam(k);
    if (l.imag() < 0) continue;
    LinearMode m;
    m.eigenvalue = l;
    const double mag = std::abs(l);
    m.natural_frequency_hz = mag / kTwoPi;
    m.damped_frequency_hz = l.imag() / kTwoPi;
    m.damping_ratio = mag > 0 ? -l.real() / mag : NAN;
    if (mag <= zero_tol) {  // a rigid-body or ignorable mode: 0 within the eigenvalue noise
      m.zero = true;
      m.eigenvalue = 0.0;
      m.natural_frequency_hz = m.damped_frequency_hz = 0.0;
      m.damping_ratio = NAN;
    }
    // each state's share of the mode's kinetic energy, Re(conj(v_i) (K v)_i): one unit (J) for metres,
    // radians and modal coordinates; a mode without kinetic energy (a drift of coordinates alone): |v_i|
    std::vector<std::pair<double, int>> part;
    const Eigen::VectorXcd v = V.col(k);
    Eigen::VectorXcd Kv = Eigen::VectorXcd::Zero(n);
    if (lin.kinetic.rows() == n) Kv = lin.kinetic.cast<std::complex<double>>() * v;
    double energy = 0;
    for (int i = 0; i < n; ++i) energy += std::abs((std::conj(v(i)) * Kv(i)).real());
    const double K_scale = lin.kinetic.rows() == n && n ? lin.kinetic.cwiseAbs().maxCoeff() : 0.0;
    const bool by_energy = energy > 1e-12 * K_scale * v.squaredNorm();
    for (int i = 0; i < n; ++i) {
      double p = by_energy ? std::abs((std::conj(v(i)) * Kv(i)).real()) : std::abs(v(i));
      if (!by_energy && i >= nqt && mag > 1e-12) p /= mag;
      part.push_back({p, i});
    }
    std::sort(part.begin(), part.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    for (int i = 0; i < std::min(3, n); ++i)
      if (part[i].first > 0.1 * part[0].first) m.dominant_states.push_back(lin.state_names[part[i].second]);
    out.push_back(m);
  }
  std::sort(out.begin(), out.end(), [](const LinearMode& a, const LinearMode& b) {
    return std::abs(a.eigenvalue) < std::abs(b.eigenvalue);
  });
  return out;
}

nlohmann::ordered_json to_json(const LinearModel& lin, const std::vector<LinearMode>& modes) {
  auto mat = [](const MatX& M) {
    auto rows = nlohmann::ordered_json::array();
    for (Eigen::Index r = 0; r < M.rows(); ++r) {
      auto row = nlohmann::ordered_json::array();
      for (Eigen::Index c = 0; c < M.cols(); ++c) row.push_back(M(r, c));
      rows.push_back(row);
    }
    return rows;
  };
  auto vec = [](const VecX& v) { return std::vector<double>(v.data(), v.data() + v.size()); };
  nlohmann::ordered_json j;
  j["method"] = lin.method;
  j["attitude"] =
      "each free joint's quaternion is replaced by a small rotation in body axes, q = q0 (x) [1; r/2] "
      "(states q.<body>.rx, .ry, .rz); attitude outputs likewise (rows <sensor>.rx, .ry, .rz)";
  j["frame"] = lin.frame;
  if (lin.frame == "lvlh")
    j["frame_note"] =
        "the free root body relative to the orbit frame (docs/gnc.md, \"Linear models in orbit\"): lvlh.x the "
        "along-track arc, lvlh.y the offset against the orbit normal, lvlh.z the drop towards nadir (m), carried "
        "round at the orbit rate n; lvlh.rx, .ry, .rz its attitude relative to the local orbit frame (a small "
        "rotation in body axes); lvlh.vx .. vz their rates, lvlh.wx .. wz its angular velocity relative to the "
        "local orbit frame (B components)";
  j["equilibrium"] = lin.equilibrium;
  j["residual"] = lin.residual;
  j["relative_equilibrium"] = lin.relative_equilibrium;
  j["ignorable"] = lin.ignorable;
  j["ignorable_dropped"] = lin.ignorable_dropped;
  j["ignorable_kept_for_outputs"] = lin.ignorable_kept_for_outputs;
  j["note"] = lin.equilibrium
                  ? "the point is an equilibrium (max |x_dot| <= 1e-9): x_dot = A dx + B dw"
                  : lin.relative_equilibrium
                  ? fmt::format("the point is a relative equilibrium: x_dot is zero (<= 1e-9) except for the ignorable "
                                "coordinates ({}), which nothing else depends on: x_dot = x0_dot + A dx + B dw with "
                                "x0_dot their steady rates (--drop-ignorable leaves them out)",
                                fmt::join(lin.ignorable, ", "))
                  : fmt::format("the point is not an equilibrium (max |x_dot| = {:.3g}): a first-order Taylor model "
                                "x_dot = x0_dot + A dx + B dw, y = y0 + C dx + D dw",
                                lin.residual);
  j["state_names"] = lin.state_names;
  j["input_names"] = lin.input_names;
  j["output_names"] = lin.output_names;
  j["A"] = mat(lin.A);
  j["B"] = mat(lin.B);
  j["C"] = mat(lin.C);
  j["D"] = mat(lin.D);
  j["x0_dot"] = vec(lin.x0_dot);
  j["y0"] = vec(lin.y0);
  auto jm = nlohmann::ordered_json::array();
  for (const LinearMode& m : modes)
    jm.push_back({{"eigenvalue", {m.eigenvalue.real(), m.eigenvalue.imag()}},
                  {"natural_frequency_hz", m.natural_frequency_hz},
                  {"damped_frequency_hz", m.damped_frequency_hz},
                  {"damping_ratio", std::isnan(m.damping_ratio) ? nlohmann::ordered_json() : nlohmann::ordered_json(m.damping_ratio)},
                  {"zero", m.zero},
                  {"dominant_states", m.dominant_states}});
  j["modes"] = jm;
  return j;
}

}  // namespace kanegen
