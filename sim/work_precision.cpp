// `kanegen bench`: work-precision diagrams. Definitions (reference method,
// error metric, invariants, timing) are in work_precision.hpp.
#include "sim/work_precision.hpp"

#include "model/invariants.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "engine/generic_engine.hpp"
#include "engine/model_checks.hpp"
#include "engine/resources.hpp"
#include "model/diagnostics.hpp"
#include "engine/load_model.hpp"
#include "model/output_file.hpp"
#include "model/state_io.hpp"
#include "sim/integrators.hpp"
#include "sim/mass_properties.hpp"
#include "sim/motion_about_com.hpp"
#include "sim/simulate.hpp"

namespace kanegen::bench {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kTargets[] = {1e-4, 1e-6, 1e-8};
/// A warm-up run longer than this is itself the (single) measurement.
constexpr double kLongRunSeconds = 2.0;

// ---- error metric ---------------------------------------------------------------

enum class Kind { length, angle, deflection, velocity, angular_rate, deflection_rate, attitude, none };

const char* kind_name(Kind k) {
  switch (k) {
    case Kind::length: return "length";
    case Kind::angle: return "angle";
    case Kind::deflection: return "deflection";
    case Kind::velocity: return "velocity";
    case Kind::angular_rate: return "angular rate";
    case Kind::deflection_rate: return "deflection rate";
    case Kind::attitude: return "attitude";
    case Kind::none: return "none";
  }
  return "?";
}

/// Kind of every component of x = [q; u]; attitude marks the 4 quaternion entries.
std::vector<Kind> component_kinds(const Model& m) {
  std::vector<Kind> k(m.nq + m.nu, Kind::none);
  for (const Body& b : m.bodies) {
    const int q = b.q_joint, u = m.nq + b.u_joint;
    if (!b.joint.prescribed()) {
      const JointTraits& t = joint_traits(b.joint.type);
      for (int i = 0; i < t.nq(); ++i)
        k[q + i] = t.units[i] == "rad" ? Kind::angle : t.units[i] == "m" ? Kind::length : Kind::attitude;
      for (int i = 0; i < t.nu(); ++i) k[u + i] = speed_is_angular(t, i) ? Kind::angular_rate : Kind::velocity;
    }
    for (int i = 0; i < b.n_modes(); ++i) k[b.q_eta + i] = Kind::deflection, k[m.nq + b.u_eta + i] = Kind::deflection_rate;
  }
  return k;
}

/// The model's size: the largest joint offset, com offset or node position (>= 1e-3 m).
double model_length(const Model& m) {
  double L = 1e-3;
  for (const Body& b : m.bodies) {
    L = std::max({L, b.joint.p_PJ.norm(), b.rigid.com_B.norm()});
    if (b.flex)
      for (const ModalNode& n : b.flex->nodes) L = std::max(L, n.rho_B.norm());
  }
  return L;
}

double kind_floor(Kind k, double L) {
  switch (k) {
    case Kind::length:
    case Kind::velocity:
    case Kind::deflection:
    case Kind::deflection_rate: return 1e-3 * L;
    case Kind::angle:
    case Kind::angular_rate: return 1e-3;
    default: return 1.0;
  }
}

/// Per component of x: the factor taking it to physical units. A modal
/// coordinate (or speed) times its mode's largest nodal translation is the
/// largest deflection (deflection rate) it causes, in m (m/s); 1 otherwise.
VecX physical_factors(const Model& m) {
  VecX f = VecX::Ones(m.nq + m.nu);
  for (const Body& b : m.bodies) {
    if (!b.flex) continue;
    for (int j = 0; j < b.n_modes(); ++j) {
      double phi = 0;
      for (int k = 0; 3 * k + 2 < b.flex->Phi.rows(); ++k) phi = std::max(phi, b.flex->Phi.block<3, 1>(3 * k, j).norm());
      if (phi > 0) f(b.q_eta + j) = f(m.nq + b.u_eta + j) = phi;
    }
  }
  return f;
}

std::string component_name(const Model& m, int i) {
  return i < m.nq ? m.q_names[i] : m.u_names[i - m.nq];
}

// ---- runs -------------------------------------------------------------------------

struct Config {
  std::string label;  ///< CSV integrator column
  IntegratorKind kind = IntegratorKind::cvode_bdf;
  bool use_jacobian = true;
};

struct RunOutput {
  bool ok = false;
  bool over_budget = false;  ///< stopped by the time budget (not a failure of the method)
  std::string message;
  IntegratorStats stats;
  double wall = NAN;
  Trajectory traj;
};

RunOutput run_once(Engine& engine, const State& s0, const Config& c, double tol_or_h, double t_end, double dt_out,
                   double budget_s, long max_steps = IntegratorOptions{}.max_steps) {
  RunOutput r;
  std::string failure;
  OdeProblem p = make_ode_problem(engine, s0.tau, &failure, c.use_jacobian, c.kind != IntegratorKind::rk4);
  // Time budget: checked every 256 rhs evaluations; an exceeded budget is an
  // unrecoverable rhs failure, which ends the run.
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(budget_s));
  bool over_budget = false;
  long count = 0;
  auto inner = std::move(p.rhs);
  p.rhs = [&, inner](double t, const double* x, double* xdot) -> int {
    if ((++count & 255) == 0 && Clock::now() > deadline) {
      over_budget = true;
      return -1;
    }
    return inner(t, x, xdot);
  };
  IntegratorOptions io;
  io.kind = c.kind;
  io.max_steps = max_steps;
  if (c.kind == IntegratorKind::rk4) {
    io.h = tol_or_h;
  } else {
    io.rtol = tol_or_h;
    io.atol = std::max(1e-2 * tol_or_h, 1e-16);
  }
  r.traj.t.reserve(64);
  r.traj.x.reserve(64);
  VecX x0(s0.q.size() + s0.u.size());
  x0 << s0.q, s0.u;
  auto out = [&](double t, const Eigen::VectorXd& x) {
    r.traj.t.push_back(t);
    r.traj.x.push_back(x);
    return true;
  };
  const auto start = Clock::now();
  try {
    r.stats = integrate(p, io, s0.t, x0, t_end, dt_out, out);
    r.ok = true;
  } catch (const IntegrationError& e) {
    r.over_budget = over_budget;
    r.message = over_budget ? fmt::format("time budget of {:g} s exceeded", budget_s) : e.reason;
    if (!over_budget && !failure.empty()) r.message += "; " + failure;
  } catch (const std::exception& e) {
    r.message = e.what();
  }
  r.wall = std::chrono::duration<double>(Clock::now() - start).count();
  return r;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string csv_quote(const std::string& s) {
  std::string out = "\"";
  for (char ch : s) {
    if (ch == '"') out += '"';
    out += (ch == '\n' || ch == '\r') ? ' ' : ch;
  }
  return out + "\"";
}

std::string num(double v) { return std::isfinite(v) ? fmt::format("{:.6e}", v) : ""; }

std::string short_time(double s) {
  if (!std::isfinite(s)) return "—";
  if (s < 1e-3) return fmt::format("{:.3g} ms", s * 1e3);
  return fmt::format("{:.3g} s", s);
}

/// A plotting script failed: the bench's numbers are written, its figure is not.
class PlotError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

std::string python_exe() {
  if (const char* e = std::getenv("KANEGEN_PYTHON"); e && *e) return e;
  return fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
}

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char ch : s) out += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return out + "'";
}


struct Curve {
  std::string engine, label;
  std::vector<const RunRecord*> points;  ///< sweep order
  std::vector<std::pair<double, double>> error_wall() const {
    std::vector<std::pair<double, double>> v;
    for (const RunRecord* r : points)
      if (r->status == "ok" && std::isfinite(r->error) && std::isfinite(r->wall_s)) v.emplace_back(r->error, r->wall_s);
    return v;
  }
};

}  // namespace

Drifts invariant_drifts(Engine& g, const InvariantSet& inv, const Trajectory& tr) {
  Drifts d;
  const Model& m = g.model();
  double total_mass = 0;
  for (const Body& b : m.bodies) total_mass += b.total_mass;
  if (tr.x.empty()) return d;
  VecX q, u;
  auto split = [&](const VecX& x) {
    q = x.head(m.nq);
    u = x.tail(m.nu);
  };
  // in a central field the scales are the motion about the centre of mass, the orbit's share apart
  d.about_com = m.central.has_value() && all_roots_free(m);
  d.H_z = inv.momentum_z && !inv.momentum;
  double Tc_max = 0;  // max kinetic energy about the centre of mass (central field), else max T
  Vec3 Hc0 = Vec3::Zero();
  for (std::size_t k = 0; k < tr.x.size() && (inv.energy || inv.momentum || inv.momentum_z); ++k) {
    split(tr.x[k]);
    if (d.about_com) {
      const auto c = motion_about_centre_of_mass(g, 0.0, q, u);
      if (!c) {
        d.about_com = false;
        continue;
      }
      Tc_max = std::max(Tc_max, c->T_c);
      if (k == 0) Hc0 = c->H_c_N;
    } else {
      Tc_max = std::max(Tc_max, g.energy(q, u).T);
    }
  }
  if (d.about_com && !(Tc_max > 0)) d.about_com = false;  // a point mass: no motion about its centre of mass
  if (inv.energy) {
    double e0 = 0, scale = 0, worst = 0;
    for (std::size_t k = 0; k < tr.x.size(); ++k) {
      split(tr.x[k]);
      const EnergyValues E = g.energy(q, u);
      if (k == 0) e0 = E.T + E.V;
      scale = std::max(scale, E.T + std::abs(E.V));
      worst = std::max(worst, std::abs(E.T + E.V - e0));
    }
    d.energy_abs = worst;
    d.E_total = std::abs(e0);
    d.energy_scale = d.about_com ? Tc_max : scale;
    d.energy = d.energy_scale > 0 ? worst / d.energy_scale : worst;
  }
  if (inv.momentum || inv.momentum_z) {
    Vec3 H0 = Vec3::Zero(), p0 = Vec3::Zero();
    double Tmax = 0, wH = 0, wp = 0;
    for (std::size_t k = 0; k < tr.x.size(); ++k) {
      split(tr.x[k]);
      const MomentumValues M = g.momentum(q, u);
      Tmax = std::max(Tmax, g.energy(q, u).T);
      if (k == 0) H0 = M.H_N, p0 = M.p_N;
      wH = std::max(wH, d.H_z ? std::abs(M.H_N.z() - H0.z()) : (M.H_N - H0).norm());
      wp = std::max(wp, (M.p_N - p0).norm());
    }
    // the momentum the motion would carry with all its kinetic energy in a rotation about the largest
    // principal axis: the floor below which |H0| is not a scale (a zero H gives no false alarm)
    split(tr.x[0]);
    State s0;
    s0.t = tr.t.empty() ? 0.0 : tr.t[0];
    s0.q = q;
    s0.u = u;
    const double I_max = system_mass_properties(m, s0).principal_moments.maxCoeff();
    const double H_motion = std::sqrt(2.0 * Tc_max * std::max(I_max, 0.0));
    const double H_ref = d.about_com ? (d.H_z ? std::abs(Hc0.z()) : Hc0.norm()) : (d.H_z ? std::abs(H0.z()) : H0.norm());
    d.H_abs = wH;
    d.H_total = d.H_z ? std::abs(H0.z()) : H0.norm();
    d.H_scale = std::max(H_ref, H_motion);
    d.H = d.H_scale > 0 ? wH / d.H_scale : wH;
    if (inv.momentum) {
      const double pscale = std::sqrt(2 * total_mass * Tmax);
      d.p = pscale > 0 ? wp / pscale : wp;
    }
  }
  return d;
}


// ---- public helpers ---------------------------------------------------------------

double rotation_angle(const Eigen::Vector4d& qa_in, const Eigen::Vector4d& qb_in) {
  const Eigen::Vector4d qa = qa_in.normalized(), qb = qb_in.normalized();
  // q_a* (x) q_b = [<qa, qb>, wa vb - wb va - va x vb]
  const double w = qa.dot(qb);
  const Eigen::Vector3d va = qa.tail<3>(), vb = qb.tail<3>();
  const Eigen::Vector3d v = qa(0) * vb - qb(0) * va - va.cross(vb);
  return 2.0 * std::atan2(v.norm(), std::abs(w));
}

ErrorMeasure trajectory_error(const Model& model, const Trajectory& run, const Trajectory& ref) {
  if (run.t.size() != ref.t.size())
    throw std::invalid_argument(
        fmt::format("trajectory_error: {} output times against {} in the reference", run.t.size(), ref.t.size()));
  const double span = ref.t.empty() ? 1.0 : std::max(1e-300, std::abs(ref.t.back() - ref.t.front()));
  for (std::size_t k = 0; k < run.t.size(); ++k)
    if (std::abs(run.t[k] - ref.t[k]) > 1e-9 * span)
      throw std::invalid_argument(
          fmt::format("trajectory_error: output time {} is {} against {} in the reference", k, run.t[k], ref.t[k]));
  const std::vector<Kind> kinds = component_kinds(model);
  const int n = static_cast<int>(kinds.size());
  const double L = model_length(model);
  const VecX unit = physical_factors(model);
  std::map<Kind, double> scale;
  for (const VecX& x : ref.x)
    for (int i = 0; i < n; ++i)
      if (kinds[i] != Kind::attitude && kinds[i] != Kind::none)
        scale[kinds[i]] = std::max(scale[kinds[i]], unit(i) * std::abs(x(i)));
  for (auto& [k, s] : scale) s = std::max(s, kind_floor(k, L));
  std::map<int, std::string> attitude_body;  // q index of each free joint's quaternion -> body name
  for (const auto& slot : model.quaternions) attitude_body[slot.q] = model.bodies[slot.body].name;

  ErrorMeasure e;
  for (std::size_t k = 0; k < run.x.size(); ++k) {
    const VecX& a = run.x[k];
    const VecX& r = ref.x[k];
    for (int i = 0; i < n; ++i) {
      double err;
      std::string where;
      if (kinds[i] == Kind::attitude) {
        if (!attitude_body.count(i)) continue;  // judged once per quaternion, at its w entry
        err = rotation_angle(a.segment<4>(i), r.segment<4>(i));
        where = "attitude " + attitude_body.at(i);
      } else if (kinds[i] == Kind::none) {
        continue;
      } else {
        err = unit(i) * std::abs(a(i) - r(i)) / scale[kinds[i]];
        where = fmt::format("{} {}", kind_name(kinds[i]), component_name(model, i));
      }
      if (!(err <= e.error)) {  // also takes a NaN
        e.error = err;
        e.worst = where;
        e.worst_t = run.t[k];
        if (std::isnan(err)) return e;
      }
    }
  }
  return e;
}

InvariantSet invariants_of(const Model& model, const VecX& tau) {
  const Invariants inv = kanegen::invariants_of(model, tau, VecX::Zero(model.nw), false);  // model/invariants.hpp
  return InvariantSet{inv.energy, inv.momentum};
}

std::optional<double> time_to_reach(const std::vector<std::pair<double, double>>& ew, double target) {
  std::optional<double> best;
  for (std::size_t k = 0; k < ew.size(); ++k) {
    const auto [e2, t2] = ew[k];
    if (!(e2 <= target)) continue;
    double t = t2;
    if (!best && k > 0) {  // the first point reaching the target: interpolate from the one before it
      const auto [e1, t1] = ew[k - 1];
      if (e1 > target && e2 > 0 && t1 > 0 && t2 > t1) {
        const double f = (std::log(target) - std::log(e1)) / (std::log(e2) - std::log(e1));
        t = std::exp(std::log(t1) + f * (std::log(t2) - std::log(t1)));
      }
    }
    best = best ? std::min(*best, t) : t;  // a later (tighter) point may still be cheaper: timing noise
  }
  return best;
}

double default_t_end(const std::string& model_path) {
  std::ifstream in(model_path);
  const std::string num_re = R"(([0-9]+(?:\.[0-9]*)?(?:[eE][-+]?[0-9]+)?))";
  const std::regex bench_re(R"(bench\s*[-_: ]\s*t[-_]end\s*[:=]?\s*)" + num_re, std::regex::icase);
  const std::regex tend_re(R"((?:^|[^-a-z_])t[-_]end\s*[:=]\s*)" + num_re, std::regex::icase);
  const std::regex cli_re(R"(--t-end[ =]+)" + num_re);
  std::optional<double> bench, tend, cli;
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    const auto hash = line.find('#');
    if (hash == std::string::npos) continue;
    const std::string c = line.substr(hash + 1);
    if (!bench && std::regex_search(c, m, bench_re)) bench = std::stod(m[1]);
    else if (!tend && std::regex_search(c, m, tend_re)) tend = std::stod(m[1]);
    if (!cli && std::regex_search(c, m, cli_re)) cli = std::stod(m[1]);
  }
  for (const auto& v : {bench, tend, cli})
    if (v && *v > 0) return *v;
  return 10.0;
}

// ---- one model ---------------------------------------------------------------------

std::vector<RunRecord> bench_model(const std::string& model_path, const BenchOptions& opt_in, std::string& md) {
  BenchOptions opt = opt_in;
  if (opt.tolerances.empty())
    opt.tolerances = opt.quick ? std::vector<double>{1e-4, 1e-7} : std::vector<double>{1e-4, 1e-6, 1e-8, 1e-10};
  std::sort(opt.tolerances.begin(), opt.tolerances.end(), std::greater<>());
  if (opt.quick) opt.repeats = 1;
  opt.repeats = std::max(1, opt.repeats);

  Model model = load_model(model_path);
  check_mass_matrix_at_initial_state(model);
  const State s0 = initial_state(model);
  const double t_end = opt.t_end ? *opt.t_end : default_t_end(model_path);
  if (!(t_end > s0.t)) throw InputError(Diagnostic{"--t-end", 0, "", "must be after the initial time"});
  const double dt_out = (t_end - s0.t) / std::max(1, opt.n_outputs);
  fmt::print(stderr, "bench {}: t_end {} s, nq {}, nu {}\n", model.name, t_end, model.nq, model.nu);
  GenericEngine reference_engine(model);
  const InvariantSet inv = invariants_of(model, s0.tau);

  // --- references
  bool need_erk = false, need_bdf = false;
  for (const std::string& n : opt.integrators)
    (n == "arkode-erk" || n == "arkode-dirk" ? need_bdf : need_erk) = true;
  const double min_tol = *std::min_element(opt.tolerances.begin(), opt.tolerances.end());
  const double ref_tol = std::max(1e-14, std::min(1e-13, 1e-3 * min_tol));
  const double ref_budget = std::max(600.0, 10 * opt.max_run_seconds);
  struct Ref {
    std::string name;
    double tol;
    RunOutput run;
  };
  std::optional<Ref> ref_erk, ref_bdf;
  // BDF's global error at a given tolerance is several times larger than
  // DP5's: its reference runs one decade tighter (then they agree to ~1e-11).
  const double ref_tol_bdf = std::max(1e-15, 0.1 * ref_tol);
  auto make_ref = [&](IntegratorKind kind, const char* label, double tol) {
    Config c{label, kind, false};
    Ref r{label, tol, run_once(reference_engine, s0, c, tol, t_end, dt_out, ref_budget, 0 /* no step limit */)};
    fmt::print(stderr, "  reference {} (generic, rtol {:g}): {}\n", label, tol,
               r.run.ok ? fmt::format("{}", r.run.stats.summary()) : "FAILED: " + r.run.message);
    return r;
  };
  if (need_erk) ref_erk = make_ref(IntegratorKind::arkode_erk, "arkode-erk", ref_tol);
  if (need_bdf) ref_bdf = make_ref(IntegratorKind::cvode_bdf, "cvode-bdf", ref_tol_bdf);
  // RK4 steps: multiples of the reference's mean step (DP5 at 1e-13 steps at
  // about 1/400 of the solution's time scale, or at its stability limit), so
  // the sweep spans errors ~1e-3..1e-11 whatever the model's time scale.
  std::vector<double> steps = opt.rk4_steps;
  if (steps.empty()) {
    const bool from_ref = ref_erk && ref_erk->run.ok && ref_erk->run.stats.steps > 0;
    const double h_ref = from_ref ? (t_end - s0.t) / ref_erk->run.stats.steps : dt_out / 400;
    for (double f : opt.quick ? std::vector<double>{32, 4} : std::vector<double>{64, 16, 4, 1}) {
      const double n = std::max(1.0, std::round(dt_out / (f * h_ref)));  // equal steps between outputs
      steps.push_back(dt_out / n);
    }
  }
  std::sort(steps.begin(), steps.end(), std::greater<>());
  steps.erase(std::unique(steps.begin(), steps.end()), steps.end());
  std::optional<ErrorMeasure> ref_agreement;
  if (ref_erk && ref_bdf && ref_erk->run.ok && ref_bdf->run.ok)
    ref_agreement = trajectory_error(model, ref_bdf->run.traj, ref_erk->run.traj);

  // --- sweeps
  std::vector<RunRecord> records;
  records.reserve(opt.engines.size() * opt.integrators.size() * std::max(steps.size(), opt.tolerances.size()));
  std::vector<std::string> notes;
  for (const std::string& engine_name : opt.engines) {
    std::unique_ptr<Engine> engine;
    std::string engine_error;
    try {
      if (engine_name == "generic") engine = std::make_unique<GenericEngine>(model);
      else if (opt.make_engine) engine = opt.make_engine(model, engine_name);
      else throw std::runtime_error("no engine factory for '" + engine_name + "'");
    } catch (const std::exception& e) {
      engine_error = e.what();
    }
    MatX probe;
    bool has_jac = false;
    if (engine) {
      try {
        has_jac = engine->jacobian(s0.t, s0.q, s0.u, s0.tau, probe);
      } catch (const std::exception&) {
      }
    }
    std::vector<Config> configs;
    std::set<std::string> seen;
    for (const std::string& n : opt.integrators) {
      Config c;
      if (n == "cvode-bdf-fd") {
        c = {"cvode-bdf-fd", IntegratorKind::cvode_bdf, false};
      } else {
        c.kind = integrator_from_string(n);
        c.use_jacobian = has_jac;
        c.label = n;
        if (n == "cvode-bdf" && !has_jac) {
          c.label = "cvode-bdf-fd";
          notes.push_back(fmt::format("the {} engine has no exact Jacobian: its cvode-bdf is cvode-bdf-fd", engine_name));
        }
      }
      if (seen.insert(c.label).second) configs.push_back(c);
    }
    for (const Config& c : configs) {
      const bool is_rk4 = c.kind == IntegratorKind::rk4;
      const std::vector<double>& sweep = is_rk4 ? steps : opt.tolerances;
      const Ref* ref = nullptr;
      if (c.kind == IntegratorKind::arkode_erk || c.kind == IntegratorKind::arkode_dirk) ref = ref_bdf ? &*ref_bdf : nullptr;
      else ref = ref_erk ? &*ref_erk : nullptr;
      bool skip_rest = false;
      for (double v : sweep) {
        RunRecord rec;
        rec.model = model.name;
        rec.engine = engine_name;
        rec.integrator = c.label;
        rec.tolerance_or_step = v;
        if (!engine) {
          rec.status = "failed";
          rec.message = "engine unavailable: " + engine_error;
          records.push_back(rec);
          continue;
        }
        if (skip_rest) {
          rec.status = "skipped";
          rec.message = "a looser sweep point exceeded the time budget";
          records.push_back(rec);
          continue;
        }
        RunOutput warm = run_once(*engine, s0, c, v, t_end, dt_out, opt.max_run_seconds);
        if (!warm.ok) {
          rec.status = "failed";
          rec.message = warm.message;
          rec.wall_s = warm.wall;
          if (warm.over_budget) skip_rest = true;
          fmt::print(stderr, "  {:<9} {:<13} {:<9.3g} FAILED: {:.160}\n", engine_name, c.label, v, warm.message);
          records.push_back(rec);
          continue;
        }
        std::vector<double> walls;
        IntegratorStats stats = warm.stats;
        if (warm.wall > kLongRunSeconds) {
          walls.push_back(warm.wall);
        } else {
          for (int k = 0; k < opt.repeats; ++k) {
            RunOutput r = run_once(*engine, s0, c, v, t_end, dt_out, opt.max_run_seconds);
            if (r.ok) walls.push_back(r.wall), stats = r.stats;
          }
          if (walls.empty()) walls.push_back(warm.wall);
        }
        rec.wall_s = median(walls);
        rec.steps = stats.steps;
        rec.rhs_evals = stats.rhs_evals;
        rec.jac_evals = stats.jac_evals;
        if (ref && ref->run.ok) {
          const ErrorMeasure e = trajectory_error(model, warm.traj, ref->run.traj);
          rec.error = e.error;
          rec.message = fmt::format("largest error: {} at t = {:.6g}", e.worst, e.worst_t);
        } else {
          rec.message = "no reference solution";
        }
        const Drifts d = invariant_drifts(reference_engine, inv, warm.traj);
        rec.energy_drift = d.energy, rec.H_drift = d.H, rec.p_drift = d.p;
        fmt::print(stderr, "  {:<9} {:<13} {:<9.3g} {:>10}  {:>7} steps  error {:.2e}\n", engine_name, c.label, v,
                   short_time(rec.wall_s), rec.steps, rec.error);
        records.push_back(rec);
      }
    }
  }

  // --- CSV
  fs::create_directories(opt.out_dir);
  const std::string csv_path = (fs::path(opt.out_dir) / (model.name + "_work_precision.csv")).string();
  {
    OutputFile file(csv_path);  // complete or untouched
    std::ostream& csv = file.stream();
    csv << "model,engine,integrator,tolerance_or_step,wall_s,steps,rhs_evals,jac_evals,error,energy_drift,H_drift,"
           "status,p_drift,message\n";
    for (const RunRecord& r : records)
      csv << fmt::format("{},{},{},{:.6g},{},{},{},{},{},{},{},{},{},{}\n", r.model, r.engine, r.integrator,
                         r.tolerance_or_step, num(r.wall_s), r.steps, r.rhs_evals, r.jac_evals, num(r.error),
                         num(r.energy_drift), num(r.H_drift), r.status, num(r.p_drift), csv_quote(r.message));
    file.commit();
  }
  fmt::print(stderr, "  wrote {}\n", csv_path);

  // --- summary section
  std::vector<Curve> curves;
  for (const RunRecord& r : records) {
    auto it = std::find_if(curves.begin(), curves.end(),
                           [&](const Curve& c) { return c.engine == r.engine && c.label == r.integrator; });
    if (it == curves.end()) curves.push_back({r.engine, r.integrator, {}}), it = curves.end() - 1;
    it->points.push_back(&r);
  }
  md += fmt::format("## {}\n\n", model.name);
  md += fmt::format("`{}`: nq = {}, nu = {}, t_end = {:g} s, errors at {} equally spaced output times; PNG: "
                    "`{}_work_precision.png`, CSV: `{}_work_precision.csv`.\n\n",
                    model_path, model.nq, model.nu, t_end, opt.n_outputs + 1, model.name, model.name);
  std::string refs;
  auto ref_line = [&](const std::optional<Ref>& r, const char* used_for) {
    if (!r) return;
    refs += fmt::format("- reference for {}: {} on the generic engine at rtol {:g}, atol {:g}: {}\n", used_for, r->name,
                        r->tol, std::max(1e-2 * r->tol, 1e-16),
                        r->run.ok ? fmt::format("{} steps, {}", r->run.stats.steps, short_time(r->run.wall))
                                  : "FAILED: " + r->run.message);
  };
  ref_line(ref_erk, "cvode-*, rk4");
  ref_line(ref_bdf, "arkode-*");
  md += refs;
  if (ref_agreement)
    md += fmt::format("- the two references differ by {:.2e} (relative error metric; largest in {}): errors below "
                      "that are not resolved\n",
                      ref_agreement->error, ref_agreement->worst);
  if (ref_tol > 1e-3 * min_tol + 1e-300)
    md += fmt::format("- WARNING: the reference is only {:.1f} orders tighter than the tightest tolerance\n",
                      std::log10(min_tol / ref_tol));
  md += fmt::format("- invariants judged: {}\n",
                    inv.energy && inv.momentum ? "energy, H and p"
                    : inv.energy               ? "energy (H, p: gravity, grounded joints or inputs)"
                    : inv.momentum             ? "H and p (energy: dampers, modal damping or inputs)"
                                               : "none (dissipation and gravity/grounded joints)");
  std::sort(notes.begin(), notes.end());
  notes.erase(std::unique(notes.begin(), notes.end()), notes.end());
  for (const auto& n : notes) md += "- " + n + "\n";
  md += "\n";

  md += "Fastest configuration reaching each relative-error target (wall time interpolated log-log between the two "
        "sweep points that bracket the target, never extrapolated):\n\n";
  md += "| target | fastest (engine / integrator) | wall time | runner-up |\n|---|---|---|---|\n";
  for (double target : kTargets) {
    std::vector<std::pair<double, std::string>> ranked;
    for (const Curve& c : curves)
      if (auto t = time_to_reach(c.error_wall(), target)) ranked.emplace_back(*t, c.engine + " / " + c.label);
    std::sort(ranked.begin(), ranked.end());
    if (ranked.empty()) {
      md += fmt::format("| {:.0e} | none reached it | — | — |\n", target);
      continue;
    }
    md += fmt::format("| {:.0e} | {} | {} | {} |\n", target, ranked[0].second, short_time(ranked[0].first),
                      ranked.size() > 1 ? ranked[1].second + " (" + short_time(ranked[1].first) + ")" : "—");
  }
  md += "\nWall time to reach each target, per configuration (— : not reached in the sweep), with the smallest "
        "error measured and the worst invariant drift of the sweep:\n\n";
  md += "| engine | integrator | 1e-4 | 1e-6 | 1e-8 | best error | failed runs | energy drift | H drift |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
  for (const Curve& c : curves) {
    const auto ew = c.error_wall();
    double best = NAN, ed = NAN, hd = NAN;
    int failed = 0;
    for (const RunRecord* r : c.points) {
      if (r->status != "ok") ++failed;
      if (std::isfinite(r->error)) best = std::isfinite(best) ? std::min(best, r->error) : r->error;
      if (std::isfinite(r->energy_drift)) ed = std::isfinite(ed) ? std::max(ed, r->energy_drift) : r->energy_drift;
      if (std::isfinite(r->H_drift)) hd = std::isfinite(hd) ? std::max(hd, r->H_drift) : r->H_drift;
    }
    md += fmt::format("| {} | {} |", c.engine, c.label);
    for (double target : kTargets) {
      const auto t = time_to_reach(ew, target);
      md += " " + (t ? short_time(*t) : std::string("—")) + " |";
    }
    md += fmt::format(" {} | {} | {} | {} |\n", std::isfinite(best) ? fmt::format("{:.1e}", best) : "—",
                      failed ? fmt::format("{}/{}", failed, c.points.size()) : "0",
                      std::isfinite(ed) ? fmt::format("{:.1e}", ed) : "—",
                      std::isfinite(hd) ? fmt::format("{:.1e}", hd) : "—");
  }
  // generated / generic at equal error
  std::string ratios;
  for (const Curve& g : curves) {
    if (g.engine != "generated") continue;
    const Curve* n = nullptr;
    std::string label = g.label;
    for (const Curve& c : curves)
      if (c.engine == "generic" && c.label == g.label) n = &c;
    if (!n && g.label == "cvode-bdf")
      for (const Curve& c : curves)
        if (c.engine == "generic" && c.label == "cvode-bdf-fd") n = &c, label = "cvode-bdf (generic: FD Jacobian)";
    if (!n) continue;
    ratios += fmt::format("| {} |", label);
    for (double target : kTargets) {
      const auto a = time_to_reach(g.error_wall(), target), b = time_to_reach(n->error_wall(), target);
      ratios += a && b ? fmt::format(" {:.2f} |", *a / *b) : std::string(" — |");
    }
    ratios += "\n";
  }
  if (!ratios.empty())
    md += "\nWall time generated / generic at equal error (same integrator; < 1: the generated engine is faster):\n\n"
          "| integrator | 1e-4 | 1e-6 | 1e-8 |\n|---|---|---|---|\n" +
          ratios;
  std::string failures;
  for (const RunRecord& r : records)
    if (r.status == "failed")
      failures += fmt::format("- {} / {} at {:g}: {:.300}\n", r.engine, r.integrator, r.tolerance_or_step, r.message);
  if (!failures.empty()) md += "\nFailed runs:\n\n" + failures;
  md += "\n";

  // --- plot
  if (opt.plot) {
    const std::string script = (fs::path(data_dir()) / "scripts" / "plot_work_precision.py").string();
    const std::string png = (fs::path(opt.out_dir) / (model.name + "_work_precision.png")).string();
    const std::string cmd = fmt::format("{} {} {} -o {}", shell_quote(python_exe()), shell_quote(script),
                                        shell_quote(csv_path), shell_quote(png));
    const int rc = std::system(cmd.c_str());
    if (rc != 0) throw PlotError(fmt::format("plotting failed (exit {}): {}", rc, cmd));
    fmt::print(stderr, "  wrote {}\n", png);
  }
  return records;
}

// ---- CLI entry --------------------------------------------------------------------

int run_bench(std::vector<std::string> models, BenchOptions opt, const std::string& suite) {
  for (const std::string& n : opt.integrators) {
    if (n == "auto")
      throw InputError(Diagnostic{"--integrators", 0, "",
                                  "'auto' picks one method per run (kanegen simulate); name the methods to compare"});
    if (n != "cvode-bdf-fd") {
      try {
        (void)integrator_from_string(n);
      } catch (const std::invalid_argument& e) {
        throw InputError(Diagnostic{"--integrators", 0, "", std::string(e.what()) + ", cvode-bdf-fd"});
      }
    }
  }
  for (const std::string& e : opt.engines)
    if (e != "generated" && e != "generic")
      throw InputError(
          Diagnostic{"--engines", 0, "", fmt::format("unknown engine '{}'; expected generated or generic", e)});
  if (opt.repeats < 1) throw InputError(Diagnostic{"--repeats", 0, "", "must be at least 1"});
  for (double t : opt.tolerances)
    if (!(t > 0 && t < 1)) throw InputError(Diagnostic{"--tolerances", 0, "", fmt::format("{} is not in (0, 1)", t)});
  for (double h : opt.rk4_steps)
    if (!(h > 0)) throw InputError(Diagnostic{"--rk4-steps", 0, "", fmt::format("{} is not positive", h)});

  std::set<std::string> optional_models;  // suite members: a model that does not load is skipped
  if (!suite.empty()) {
    if (suite != "extreme") throw InputError(Diagnostic{"--suite", 0, "", "unknown suite '" + suite + "'; expected extreme"});
    fs::path dir = "models/extreme";
    if (!fs::is_directory(dir)) dir = fs::path(data_dir()) / "models" / "extreme";
    std::vector<std::string> found;
    if (fs::is_directory(dir))
      for (const auto& entry : fs::directory_iterator(dir))
        if (entry.path().extension() == ".yaml") found.push_back(entry.path().string());
    std::sort(found.begin(), found.end());
    if (found.empty()) fmt::print(stderr, "bench: no models/extreme/*.yaml found: suite 'extreme' skipped\n");
    for (const auto& f : found) models.push_back(f), optional_models.insert(f);
  }
  if (models.empty()) {
    if (!suite.empty()) return 0;
    throw InputError(Diagnostic{"MODEL", 0, "", "no model given (give MODEL... or --suite extreme)"});
  }

  std::string md = "# Work-precision summary\n\n";
  md += "Generated by `kanegen bench`. Error: max over the output times of the state error relative to the "
        "reference's scale of each kind of component (free-joint attitude as the rotation angle in rad); see "
        "sim/work_precision.hpp. Wall time: integrate() only, median of " +
        std::to_string(opt.quick ? 1 : opt.repeats) +
        " runs after a warm-up (a warm-up longer than 2 s is the only measurement). "
        "Adaptive integrators: rtol = tolerance, atol = 1e-2 tolerance; rk4: fixed step.\n\n";
  int status = 0;
  for (const std::string& path : models) {
    try {
      bench_model(path, opt, md);
    } catch (const InputError& e) {
      if (!optional_models.count(path)) throw;
      std::string msg;
      for (const Diagnostic& d : e.diagnostics()) msg += d.str() + "; ";
      fmt::print(stderr, "bench: skipping {}: {}\n", path, msg);
      md += fmt::format("## {}\n\nskipped: {}\n\n", path, msg);
    } catch (const PlotError& e) {
      fmt::print(stderr, "bench: {}: {}\n", path, e.what());
      md += fmt::format("## {}\n\nerror: {}\n\n", path, e.what());
      status = 1;
    } catch (const std::exception& e) {
      if (!optional_models.count(path)) throw;
      fmt::print(stderr, "bench: {}: {}\n", path, e.what());
      md += fmt::format("## {}\n\nerror: {}\n\n", path, e.what());
      status = 1;
    }
  }
  fs::create_directories(opt.out_dir);
  const std::string summary = (fs::path(opt.out_dir) / "summary.md").string();
  write_file_atomically(summary, md);
  fmt::print(stderr, "bench: wrote {}\n", summary);
  return status;
}

}  // namespace kanegen::bench
