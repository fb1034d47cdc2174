// `kanegen bench`: work-precision diagrams (error against wall time) of models
// x engines x integrators x tolerances (or RK4 steps).
//
// Per run: wall time of integrate() alone (median of `repeats` timed runs
// after one warm-up run that warms the caches; the engine, JIT-compiled or
// loaded from the cache, exists before it; a warm-up longer than 2 s is
// itself the single measurement: cache effects are negligible there, and it
// keeps slow sweeps affordable), steps, rhs and Jacobian evaluations, the
// error against a reference solution and the drift of the invariants that
// hold for the model. Failed runs (IntegrationError, ...) are recorded with
// their message; a run over the time budget also skips the tighter points of
// its curve.
//
// Reference (always the generic engine, never the method under test):
//   - cvode-bdf, cvode-bdf-fd, cvode-adams, rk4  ->  arkode-erk (Dormand-Prince 5(4))
//     at rtol = ref_tol = clamp(1e-3 * tightest tested tolerance, 1e-14, 1e-13)
//   - arkode-erk, arkode-dirk                    ->  cvode-bdf (FD Jacobian)
//     at rtol = ref_tol / 10: BDF's global error at equal tolerance is several
//     times DP5's; one decade tighter they agree to ~1e-11 (measured on
//     pendulum and explorer1_rigid against RK4 at h = 2e-4)
// with atol = 1e-2 rtol. The two references are compared with each other;
// their difference is reported (summary.md) as the reference's own accuracy.
// RK4 steps (default): {64, 16, 4, 1} x the arkode-erk reference's mean step,
// rounded to divide the output interval (RK4 lands on output times).
//
// Error metric (see trajectory_error): max over the output times (n_outputs
// equal intervals) and over "kinds" of state components of
//   - free-joint attitude: the rotation angle between the two quaternions,
//     2 acos|<q_a, q_b>| in rad (computed as 2 atan2(|vec(q_a* q_b)|, |<q_a,q_b>|),
//     accurate for small angles), divided by 1 rad;
//   - every other kind (length, angle, velocity, angular rate, modal
//     deflection, deflection rate): max_i |x_i - r_i| / S_kind, with S_kind
//     the largest |r_i(t)| of that kind over the reference (the reference's
//     scale), floored at 1e-3 L (lengths, deflections; L = the model's size:
//     largest joint offset, com offset or node position), 1e-3 L/s
//     (velocities, deflection rates), 1e-3 rad or rad/s (angles, angular
//     rates), so that a kind the motion barely excites is not judged against
//     its own round-off. Modal coordinates (speeds) enter as deflections:
//     multiplied by their mode's largest nodal translation |Phi|, in m (m/s).
// So the error is a relative error; the accuracy targets of summary.md
// (1e-4, 1e-6, 1e-8) apply to it directly.
//
// Invariants (judged on the model: gravity, joints to ground, dampers, inputs):
//   energy_drift = max_t |E(t) - E(0)| / max_t (T + |V|)          (no damper, no modal damping, no input)
//   H_drift      = max_t |H(t) - H(0)| / |H(0)|                   (zero gravity, only free joints to ground, no input)
//   p_drift      = max_t |p(t) - p(0)| / sqrt(2 m_total max_t T)  (same condition)
// evaluated with the generic engine at the run's output states (outside timing).
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <optional>
#include <string>
#include <vector>

#include <functional>
#include <memory>

#include "engine/engine.hpp"
#include "model/model.hpp"

namespace kanegen::bench {

struct BenchOptions {
  std::vector<std::string> engines{"generated", "generic"};
  std::vector<std::string> integrators{"rkf78",      "dopri5",      "cvode-bdf", "cvode-bdf-fd", "cvode-bdf2",
                                       "cvode-adams", "arkode-erk", "arkode-dirk", "rk4"};
  std::vector<double> tolerances;  ///< empty: 1e-4,1e-6,1e-8,1e-10 (quick: 1e-4,1e-7)
  std::vector<double> rk4_steps;   ///< empty: {64,16,4,1} (quick: {32,4}) x mean step of the DP5 reference
  std::optional<double> t_end;    ///< empty: default_t_end(model file)
  int repeats = 3;
  int n_outputs = 50;             ///< output intervals over [t0, t_end]: error and invariants at these times
  double max_run_seconds = 60;    ///< a run exceeding it fails; tighter sweep points of that curve are skipped
                                  ///< (references: max(600, 10x) and no step limit)
  std::string out_dir = "bench-out";
  bool quick = false;             ///< the quick sweeps above, 1 repeat
  bool plot = true;               ///< write the PNGs (python3 scripts/plot_work_precision.py)
  /// Makes the engine of each name in `engines` ("generic" is built in; the
  /// kanegen CLI passes one that also makes "generated" by the JIT).
  std::function<std::unique_ptr<Engine>(const Model&, const std::string&)> make_engine;
};

/// Rotation angle (rad, in [0, pi]) between the attitudes of two quaternions
/// [w, x, y, z] (any non-zero norm; q and -q are the same attitude).
double rotation_angle(const Eigen::Vector4d& qa, const Eigen::Vector4d& qb);

/// States at the output times of one run.
struct Trajectory {
  std::vector<double> t;
  std::vector<VecX> x;  ///< [q; u]
};

struct ErrorMeasure {
  double error = 0;       ///< relative error (header comment)
  std::string worst;      ///< the kind and component where the maximum is, e.g. "attitude bus" or "u bus.wx"
  double worst_t = 0;     ///< and the time
};

/// Error of `run` against `ref` (same output times) for `model` (header comment).
/// Throws std::invalid_argument when the output times differ.
ErrorMeasure trajectory_error(const Model& model, const Trajectory& run, const Trajectory& ref);

/// Which invariants hold for `model` with inputs `tau` (header comment).
struct InvariantSet {
  bool energy = false;
  bool momentum = false;
  bool momentum_z = false;  ///< H_z alone (central gravity with J2); with momentum false
};
InvariantSet invariants_of(const Model& model, const VecX& tau);

/// Relative drifts of the invariants that hold (NaN for the others) over the
/// states of a run: energy max|E - E0| / max(T + |V|); |H - H0| / |H0|;
/// |p - p0| / sqrt(2 m T_max) (m: the model's whole mass).
struct Drifts {
  double energy = NAN, H = NAN, p = NAN;
  /// The same drifts in their units (J, N m s) and the scales they are relative to (docs/decisions.md,
  /// "Reports in orbit"): in a central field the motion about the centre of mass (T_c's maximum; |H_c| or the
  /// momentum scale sqrt(2 T_c I_max)), elsewhere max(T + |V|) and max(|H0|, sqrt(2 T I_max)).
  double energy_abs = NAN, energy_scale = NAN, H_abs = NAN, H_scale = NAN;
  double E_total = NAN, H_total = NAN;  ///< |E0| and |H0| (with the orbit's share)
  bool about_com = false;               ///< the scales are the motion about the centre of mass (central field)
  bool H_z = false;                     ///< H is H_z alone
};
Drifts invariant_drifts(Engine& engine, const InvariantSet& inv, const Trajectory& tr);

/// The worse of two measures of a run's segments, NaN meaning "not measured" (not "bad").
inline double worse_measure(double a, double b) { return std::isnan(a) ? b : std::isnan(b) ? a : std::max(a, b); }

/// One sweep point.
struct RunRecord {
  std::string model, engine, integrator;  ///< integrator label, e.g. "cvode-bdf-fd"
  double tolerance_or_step = 0;
  double wall_s = NAN;
  long steps = 0, rhs_evals = 0, jac_evals = 0;
  double error = NAN, energy_drift = NAN, H_drift = NAN, p_drift = NAN;
  std::string status = "ok";  ///< ok | failed | skipped
  std::string message;        ///< failure message, or where the error is largest
};

/// Cheapest wall time at which a curve (sweep points in sweep order, loose to
/// tight) reaches `target`: the first point whose error <= target; when the
/// point before it in the sweep has a larger error, log-log interpolated
/// between the two (never extrapolated); a later point that is cheaper still
/// (timing noise) wins. nullopt if no point reaches it.
std::optional<double> time_to_reach(const std::vector<std::pair<double, double>>& error_wall, double target);

/// Default simulated time of a model file, from its comments: "bench-t-end: T"
/// (also "bench: t_end = T"), else "t_end: T" / "t-end = T", else the first
/// "--t-end T" (a suggested command line), else 10 s.
double default_t_end(const std::string& model_path);

/// Benchmarks one model; writes DIR/<model>_work_precision.csv (and .png when
/// opt.plot). Appends its section to `summary_md`. Returns the records.
std::vector<RunRecord> bench_model(const std::string& model_path, const BenchOptions& opt, std::string& summary_md);

/// `kanegen bench`: every model (plus models/extreme/*.yaml with
/// suite == "extreme"); writes DIR/summary.md. Returns the exit status.
int run_bench(std::vector<std::string> models, BenchOptions opt, const std::string& suite);

}  // namespace kanegen::bench
