// Time integration with SUNDIALS 6 (CVODE, ARKODE) and a fixed-step RK4.
//
// Method choices:
//   cvode-bdf    CVODE, BDF orders 1-5, Newton + dense direct linear solver;
//                user Jacobian if OdeProblem::jacobian is set, else SUNDIALS'
//                internal difference-quotient Jacobian.
//   cvode-adams  CVODE, Adams-Moulton orders 1-12, fixed-point iteration
//                (SUNNonlinSol_FixedPoint, no Anderson acceleration). Non-stiff.
//   arkode-erk   ARKODE ERKStep with the Dormand-Prince 5(4) table
//                (ARKODE_DORMAND_PRINCE_7_4_5, FSAL, 6 new rhs evals per
//                step). Chosen over ERKStep's default order-4 table
//                (Zonneveld 5-3-4) because it is markedly cheaper at the tight
//                tolerances used for multibody simulation.
//   arkode-dirk  ARKODE ARKStep, implicit part only, order 4 (default table
//                ARKODE_SDIRK_5_3_4), Newton + dense, user Jacobian if given;
//                linear-solver setup every step (see DirkStepper).
//   rk4          classical RK4, fixed step h; the last step before each output
//                time is shortened to land exactly on it; project() after
//                every step.
//
// Output: at t0, t0 + k*dt_out and finally exactly t_end. The adaptive
// methods take one internal step at a time (CV_ONE_STEP / ARK_ONE_STEP) until
// they pass the next output time and then interpolate there with the
// integrator's own dense output (CVodeGetDky / *GetDky) -- exactly what
// CV_NORMAL does internally, so steps are never cut by output times; the only
// stop time is t_end. Driving the steps ourselves gives an exact total step
// budget (SUNDIALS' mxstep is per call), the exact last accepted (t_n, y_n)
// on failure (ARKODE reports a stage time there), and detection of
// stagnation (t + h == t), which SUNDIALS merely warns about and would
// otherwise keep stepping until max_steps.
//
// max_steps counts steps over the whole integration; max_steps <= 0 means
// unlimited.
//
// A non-finite derivative returned by the rhs is reported to SUNDIALS as a
// recoverable failure (the step is retried with a smaller h); exceptions
// thrown by user callbacks are caught in the C trampolines, SUNDIALS is told
// about an unrecoverable failure, and the exception is rethrown unchanged
// once the SUNDIALS call returns.
#include "sim/integrators.hpp"
#include "sim/event_location.hpp"
#include "sim/odeint_integrators.hpp"
#include "sim/output_schedule.hpp"

#include <arkode/arkode_arkstep.h>
#include <arkode/arkode_erkstep.h>
#include <cvode/cvode.h>
#include <fmt/format.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <limits>
#include <memory>

namespace kanegen {

namespace {

struct KindName {
  IntegratorKind kind;
  const char* name;
};
constexpr KindName kKindNames[] = {
    {IntegratorKind::cvode_bdf, "cvode-bdf"},   {IntegratorKind::cvode_adams, "cvode-adams"},
    {IntegratorKind::arkode_erk, "arkode-erk"}, {IntegratorKind::arkode_dirk, "arkode-dirk"},
    {IntegratorKind::rk4, "rk4"},               {IntegratorKind::cvode_bdf2, "cvode-bdf2"},
    {IntegratorKind::dopri5, "dopri5"},         {IntegratorKind::rkf78, "rkf78"},
    {IntegratorKind::automatic, "auto"},
};

// ---- formatting helpers ----------------------------------------------------

std::string format_state(const Eigen::VectorXd& x) {
  constexpr Eigen::Index kMaxShown = 12;
  std::string s = "[";
  for (Eigen::Index i = 0; i < x.size() && i < kMaxShown; ++i) {
    if (i > 0) s += ", ";
    s += fmt::format("{}", x[i]);
  }
  if (x.size() > kMaxShown) s += fmt::format(", ... ({} components)", x.size());
  s += "]";
  return s;
}

std::string first_nonfinite(const double* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return fmt::format("component {} = {}", i, v[i]);
  }
  return {};
}

// ---- SUNDIALS RAII -------------------------------------------------------------

struct ContextDeleter {
  void operator()(SUNContext ctx) const { SUNContext_Free(&ctx); }
};
struct NVectorDeleter {
  void operator()(N_Vector v) const { N_VDestroy(v); }
};
struct MatrixDeleter {
  void operator()(SUNMatrix m) const { SUNMatDestroy(m); }
};
struct LinSolDeleter {
  void operator()(SUNLinearSolver s) const { SUNLinSolFree(s); }
};
struct NonlinSolDeleter {
  void operator()(SUNNonlinearSolver s) const { SUNNonlinSolFree(s); }
};
struct CVodeDeleter {
  void operator()(void* mem) const { CVodeFree(&mem); }
};
struct ERKStepDeleter {
  void operator()(void* mem) const { ERKStepFree(&mem); }
};
struct ARKStepDeleter {
  void operator()(void* mem) const { ARKStepFree(&mem); }
};

using ContextPtr = std::unique_ptr<std::remove_pointer_t<SUNContext>, ContextDeleter>;
using NVectorPtr = std::unique_ptr<std::remove_pointer_t<N_Vector>, NVectorDeleter>;
using MatrixPtr = std::unique_ptr<std::remove_pointer_t<SUNMatrix>, MatrixDeleter>;
using LinSolPtr = std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, LinSolDeleter>;
using NonlinSolPtr = std::unique_ptr<std::remove_pointer_t<SUNNonlinearSolver>, NonlinSolDeleter>;

template <class T>
T* check_alloc(T* p, const char* what) {
  if (p == nullptr) throw std::runtime_error(fmt::format("SUNDIALS: {} failed", what));
  return p;
}

// ---- callbacks -------------------------------------------------------------------

/// Shared between the C trampolines and the driver.
struct CallbackData {
  const OdeProblem* problem = nullptr;
  std::exception_ptr exception;  ///< thrown by a user callback; rethrown after SUNDIALS returns
  std::string rhs_failure;       ///< last rhs failure (nonzero return or non-finite output)
  std::string error_message;     ///< last error reported through the SUNDIALS error handler
  std::string warning_message;   ///< last warning (e.g. "t + h = t on the next step")
};

int rhs_trampoline(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) {
  auto* d = static_cast<CallbackData*>(user_data);
  try {
    const int n = d->problem->n;
    double* out = N_VGetArrayPointer(ydot);
    const int rc = d->problem->rhs(t, N_VGetArrayPointer(y), out);
    if (rc != 0) {
      d->rhs_failure = fmt::format("rhs returned {} at t = {}", rc, t);
      return rc;
    }
    std::string bad = first_nonfinite(out, n);
    if (!bad.empty()) {
      d->rhs_failure = fmt::format("rhs produced a non-finite derivative at t = {} ({})", t, bad);
      return 1;  // recoverable: retry with a smaller step
    }
    return 0;
  } catch (...) {
    d->exception = std::current_exception();
    return -1;
  }
}

int jac_trampoline(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix J, void* user_data, N_Vector, N_Vector,
                   N_Vector) {
  auto* d = static_cast<CallbackData*>(user_data);
  try {
    SUNMatZero(J);
    const int rc = d->problem->jacobian(t, N_VGetArrayPointer(y), N_VGetArrayPointer(fy), SUNDenseMatrix_Data(J));
    if (rc != 0) return rc;
    std::string bad = first_nonfinite(SUNDenseMatrix_Data(J), d->problem->n * d->problem->n);
    if (!bad.empty()) {
      d->rhs_failure = fmt::format("jacobian non-finite at t = {} ({})", t, bad);
      return 1;
    }
    return 0;
  } catch (...) {
    d->exception = std::current_exception();
    return -1;
  }
}

void error_handler(int error_code, const char* module, const char* function, char* msg, void* user_data) {
  auto* d = static_cast<CallbackData*>(user_data);
  std::string text = fmt::format("[{} {}] {}", module ? module : "?", function ? function : "?", msg ? msg : "");
  if (error_code < 0) {
    d->error_message = std::move(text);
  } else if (text.find("mxhnil times") == std::string::npos) {  // keep the informative "t + h = t" text
    d->warning_message = std::move(text);
  }
}

// ---- steppers --------------------------------------------------------------------

/// Thin uniform interface over CVODE / ERKStep / ARKStep.
class Stepper {
 public:
  virtual ~Stepper() = default;
  /// One internal step (CV_ONE_STEP / ARK_ONE_STEP); tout only guides the first step size.
  virtual int step(double tout, N_Vector y, double* tret) = 0;
  /// Interpolated solution at t within the last step.
  virtual int dense_output(double t, N_Vector y) = 0;
  virtual std::string flag_name(int flag) = 0;
  virtual void fill_stats(IntegratorStats& s) = 0;
};

void check_flag(int flag, const char* call) {
  if (flag < 0) throw std::runtime_error(fmt::format("SUNDIALS: {} failed with flag {}", call, flag));
}

std::string take_name(char* name) {
  // The *GetReturnFlagName functions return a malloc'ed string.
  std::string s = name ? name : "UNKNOWN";
  free(name);
  return s;
}

class CvodeStepper final : public Stepper {
 public:
  CvodeStepper(bool bdf, SUNContext ctx, N_Vector y, double t0, double t_end, const IntegratorOptions& opt,
               CallbackData& data, bool user_jac)
      : mem_(check_alloc(CVodeCreate(bdf ? CV_BDF : CV_ADAMS, ctx), "CVodeCreate")) {
    void* m = mem_.get();
    check_flag(CVodeSetErrHandlerFn(m, error_handler, &data), "CVodeSetErrHandlerFn");
    check_flag(CVodeInit(m, rhs_trampoline, t0, y), "CVodeInit");
    check_flag(CVodeSetUserData(m, &data), "CVodeSetUserData");
    check_flag(CVodeSStolerances(m, opt.rtol, opt.atol), "CVodeSStolerances");
    check_flag(CVodeSetStopTime(m, t_end), "CVodeSetStopTime");
    if (bdf) {
      A_.reset(check_alloc(SUNDenseMatrix(N_VGetLength(y), N_VGetLength(y), ctx), "SUNDenseMatrix"));
      LS_.reset(check_alloc(SUNLinSol_Dense(y, A_.get(), ctx), "SUNLinSol_Dense"));
      check_flag(CVodeSetLinearSolver(m, LS_.get(), A_.get()), "CVodeSetLinearSolver");
      if (user_jac) check_flag(CVodeSetJacFn(m, jac_trampoline), "CVodeSetJacFn");
      // BDF orders 3-5 are not A-stable: on lightly damped stiff oscillations
      // (flexible modes) they are driven to tiny steps (stiff_appendage, 5 s:
      // 400k steps at orders up to 5, 1.9k at order 2). cvode-bdf2 caps the
      // order at 2; stability-limit detection did not help there (530k
      // steps, docs/extreme.md), so it stays off (CVODE's default).
      if (opt.max_order > 0) check_flag(CVodeSetMaxOrd(m, opt.max_order), "CVodeSetMaxOrd");
    } else {
      NLS_.reset(check_alloc(SUNNonlinSol_FixedPoint(y, 0, ctx), "SUNNonlinSol_FixedPoint"));
      check_flag(CVodeSetNonlinearSolver(m, NLS_.get()), "CVodeSetNonlinearSolver");
    }
  }
  int step(double tout, N_Vector y, double* tret) override { return CVode(mem_.get(), tout, y, tret, CV_ONE_STEP); }
  int dense_output(double t, N_Vector y) override { return CVodeGetDky(mem_.get(), t, 0, y); }
  std::string flag_name(int flag) override { return take_name(CVodeGetReturnFlagName(flag)); }
  void fill_stats(IntegratorStats& s) override {
    void* m = mem_.get();
    long nst = 0, nfe = 0, nfeLS = 0, nje = 0, netf = 0, nncf = 0;
    CVodeGetNumSteps(m, &nst);
    CVodeGetNumRhsEvals(m, &nfe);
    if (LS_) {
      CVodeGetNumLinRhsEvals(m, &nfeLS);
      CVodeGetNumJacEvals(m, &nje);
    }
    CVodeGetNumErrTestFails(m, &netf);
    CVodeGetNumNonlinSolvConvFails(m, &nncf);
    s.steps = nst;
    s.rhs_evals = nfe + nfeLS;
    s.jac_evals = nje;
    s.error_test_failures = netf;
    s.nonlinear_failures = nncf;
  }

 private:
  // Declaration order = reverse destruction order: the integrator goes first.
  MatrixPtr A_;
  LinSolPtr LS_;
  NonlinSolPtr NLS_;
  std::unique_ptr<void, CVodeDeleter> mem_;
};

class ErkStepper final : public Stepper {
 public:
  ErkStepper(SUNContext ctx, N_Vector y, double t0, double t_end, const IntegratorOptions& opt, CallbackData& data)
      : mem_(check_alloc(ERKStepCreate(rhs_trampoline, t0, y, ctx), "ERKStepCreate")) {
    void* m = mem_.get();
    check_flag(ERKStepSetErrHandlerFn(m, error_handler, &data), "ERKStepSetErrHandlerFn");
    check_flag(ERKStepSetUserData(m, &data), "ERKStepSetUserData");
    check_flag(ERKStepSStolerances(m, opt.rtol, opt.atol), "ERKStepSStolerances");
    check_flag(ERKStepSetStopTime(m, t_end), "ERKStepSetStopTime");
    check_flag(ERKStepSetTableNum(m, ARKODE_DORMAND_PRINCE_7_4_5), "ERKStepSetTableNum");
  }
  int step(double tout, N_Vector y, double* tret) override {
    return ERKStepEvolve(mem_.get(), tout, y, tret, ARK_ONE_STEP);
  }
  int dense_output(double t, N_Vector y) override { return ERKStepGetDky(mem_.get(), t, 0, y); }
  std::string flag_name(int flag) override { return take_name(ERKStepGetReturnFlagName(flag)); }
  void fill_stats(IntegratorStats& s) override {
    long nst = 0, nfe = 0, netf = 0;
    ERKStepGetNumSteps(mem_.get(), &nst);
    ERKStepGetNumRhsEvals(mem_.get(), &nfe);
    ERKStepGetNumErrTestFails(mem_.get(), &netf);
    s.steps = nst;
    s.rhs_evals = nfe;
    s.error_test_failures = netf;
  }

 private:
  std::unique_ptr<void, ERKStepDeleter> mem_;
};

class DirkStepper final : public Stepper {
 public:
  DirkStepper(SUNContext ctx, N_Vector y, double t0, double t_end, const IntegratorOptions& opt, CallbackData& data,
              bool user_jac)
      : A_(check_alloc(SUNDenseMatrix(N_VGetLength(y), N_VGetLength(y), ctx), "SUNDenseMatrix")),
        LS_(check_alloc(SUNLinSol_Dense(y, A_.get(), ctx), "SUNLinSol_Dense")),
        mem_(check_alloc(ARKStepCreate(nullptr, rhs_trampoline, t0, y, ctx), "ARKStepCreate")) {
    void* m = mem_.get();
    check_flag(ARKStepSetErrHandlerFn(m, error_handler, &data), "ARKStepSetErrHandlerFn");
    check_flag(ARKStepSetUserData(m, &data), "ARKStepSetUserData");
    check_flag(ARKStepSStolerances(m, opt.rtol, opt.atol), "ARKStepSStolerances");
    check_flag(ARKStepSetStopTime(m, t_end), "ARKStepSetStopTime");
    check_flag(ARKStepSetOrder(m, 4), "ARKStepSetOrder");
    check_flag(ARKStepSetLinearSolver(m, LS_.get(), A_.get()), "ARKStepSetLinearSolver");
    if (user_jac) check_flag(ARKStepSetJacFn(m, jac_trampoline), "ARKStepSetJacFn");
    // Rebuild and refactor I - gamma J every step (J itself is still reused).
    // With SUNDIALS 6.4's default lagging (up to 20 steps) the Newton stage
    // solves "converge" to wrong values on oscillatory problems: on x'' = -x
    // at rtol 1e-6 the global error was 8e-4 instead of 1e-7.
    check_flag(ARKStepSetLSetupFrequency(m, 1), "ARKStepSetLSetupFrequency");
  }
  int step(double tout, N_Vector y, double* tret) override {
    return ARKStepEvolve(mem_.get(), tout, y, tret, ARK_ONE_STEP);
  }
  int dense_output(double t, N_Vector y) override { return ARKStepGetDky(mem_.get(), t, 0, y); }
  std::string flag_name(int flag) override { return take_name(ARKStepGetReturnFlagName(flag)); }
  void fill_stats(IntegratorStats& s) override {
    void* m = mem_.get();
    long nst = 0, nfe = 0, nfi = 0, nfeLS = 0, nje = 0, netf = 0, nncf = 0;
    ARKStepGetNumSteps(m, &nst);
    ARKStepGetNumRhsEvals(m, &nfe, &nfi);
    ARKStepGetNumLinRhsEvals(m, &nfeLS);
    ARKStepGetNumJacEvals(m, &nje);
    ARKStepGetNumErrTestFails(m, &netf);
    ARKStepGetNumNonlinSolvConvFails(m, &nncf);
    s.steps = nst;
    s.rhs_evals = nfe + nfi + nfeLS;
    s.jac_evals = nje;
    s.error_test_failures = netf;
    s.nonlinear_failures = nncf;
  }

 private:
  MatrixPtr A_;
  LinSolPtr LS_;
  std::unique_ptr<void, ARKStepDeleter> mem_;
};

std::string describe_flag(const std::string& name) {
  auto has = [&](const char* s) { return name.find(s) != std::string::npos; };
  if (has("TOO_MUCH_ACC")) return "too much accuracy requested for machine precision";
  if (has("ERR_FAILURE")) return "repeated error test failures (step size underflow or a singularity)";
  if (has("CONV_FAILURE")) return "repeated nonlinear solver convergence failures (step size underflow)";
  if (has("REPTD_RHSFUNC_ERR")) return "repeated recoverable rhs failures; reducing the step did not help";
  if (has("FIRST_RHSFUNC_ERR")) return "the rhs failed at the initial state";
  if (has("UNREC_RHSFUNC_ERR")) return "rhs failure that the method cannot recover from";
  if (has("RHSFUNC_FAIL")) return "unrecoverable rhs failure";
  if (has("LSETUP_FAIL")) return "linear solver setup failed (Jacobian evaluation or factorization)";
  if (has("LSOLVE_FAIL")) return "linear solver failed";
  if (has("TOO_CLOSE")) return "output time too close to the initial time";
  if (has("ILL_INPUT")) return "illegal input";
  return "integrator failure";
}

/// Consecutive steps without any progress in t (t + h == t) before giving up.
constexpr int kMaxStagnantSteps = 50;

IntegratorStats integrate_sundials(const OdeProblem& problem, const IntegratorOptions& opt, double t0,
                                   const Eigen::VectorXd& x0, double t_end, double dt_out, const OutputFn& output,
                                   IntegratorStats stats, double grid_origin) {
  const std::string name = to_string(opt.kind);
  const bool user_jac = static_cast<bool>(problem.jacobian);
  const int n = problem.n;

  SUNContext raw_ctx = nullptr;
  if (SUNContext_Create(nullptr, &raw_ctx) != 0 || raw_ctx == nullptr)
    throw std::runtime_error("SUNDIALS: SUNContext_Create failed");
  ContextPtr ctx(raw_ctx);
  NVectorPtr y(check_alloc(N_VNew_Serial(n, ctx.get()), "N_VNew_Serial"));     // state at tn
  NVectorPtr yout(check_alloc(N_VNew_Serial(n, ctx.get()), "N_VNew_Serial"));  // interpolated output
  Eigen::Map<Eigen::VectorXd> ymap(N_VGetArrayPointer(y.get()), n);
  Eigen::Map<Eigen::VectorXd> youtmap(N_VGetArrayPointer(yout.get()), n);
  ymap = x0;

  CallbackData data;
  data.problem = &problem;

  std::unique_ptr<Stepper> stepper;
  switch (opt.kind) {
    case IntegratorKind::cvode_bdf:
    case IntegratorKind::cvode_adams:
      stepper = std::make_unique<CvodeStepper>(opt.kind == IntegratorKind::cvode_bdf, ctx.get(), y.get(), t0, t_end,
                                               opt, data, user_jac);
      break;
    case IntegratorKind::cvode_bdf2: {  // BDF capped at order 2: A-stable
      IntegratorOptions o2 = opt;
      o2.max_order = opt.max_order > 0 ? std::min(opt.max_order, 2) : 2;
      stepper = std::make_unique<CvodeStepper>(true, ctx.get(), y.get(), t0, t_end, o2, data, user_jac);
      break;
    }
    case IntegratorKind::arkode_erk:
      stepper = std::make_unique<ErkStepper>(ctx.get(), y.get(), t0, t_end, opt, data);
      break;
    case IntegratorKind::arkode_dirk:
      stepper = std::make_unique<DirkStepper>(ctx.get(), y.get(), t0, t_end, opt, data, user_jac);
      break;
    case IntegratorKind::rk4:
    case IntegratorKind::dopri5:
    case IntegratorKind::rkf78:
    case IntegratorKind::automatic:
      throw std::logic_error("integrate_sundials called for " + to_string(opt.kind));
  }

  Eigen::VectorXd xo(n);
  auto emit = [&](double t, const Eigen::Map<Eigen::VectorXd>& x) {
    xo = x;
    if (problem.project) problem.project(xo.data());
    return output ? output(t, xo) : true;
  };

  double tn = t0;  // time of the last accepted step; y holds the state there
  // Error with the last accepted (tn, state). SUNDIALS leaves y_n in y on failure.
  auto fail = [&](const std::string& description, const std::string& flag_text, double tout) -> IntegrationError {
    Eigen::VectorXd x = ymap;
    std::string msg =
        fmt::format("{}: integration failed at t = {} while integrating towards t = {}: {}", name, tn, tout,
                    description);
    if (!flag_text.empty()) msg += fmt::format(" ({})", flag_text);
    if (!data.rhs_failure.empty()) msg += fmt::format("; last rhs failure: {}", data.rhs_failure);
    if (!data.error_message.empty()) msg += fmt::format("; SUNDIALS: {}", data.error_message);
    if (!data.warning_message.empty()) msg += fmt::format("; last SUNDIALS warning: {}", data.warning_message);
    return IntegrationError(msg, tn, std::move(x));
  };

  if (!emit(t0, ymap)) {
    stepper->fill_stats(stats);
    return stats;
  }

  // One internal step at a time (never cut by output times; t_end is the stop
  // time), outputs by the integrator's own interpolation. This gives an exact
  // total step budget, the exact (t_n, y_n) on failure (ARKODE reports a stage
  // time there), and lets us detect stagnation (t + h == t), which SUNDIALS
  // only warns about.
  OutputSchedule schedule(t0, t_end, dt_out, grid_origin);
  EventLocator events(problem);
  events.reset(t0, ymap.data());
  auto dense = [&](double t, double tout_now) {
    const int flag = stepper->dense_output(t, yout.get());
    if (flag < 0) {
      const std::string fname = stepper->flag_name(flag);
      throw fail("dense output failed", fmt::format("{}, flag {}", fname, flag), tout_now);
    }
  };
  double tout = t0;
  long nsteps = 0;
  int stagnant = 0;
  while (schedule.next(tout)) {
    while (tn < tout) {
      const double t_before = tn;
      if (opt.max_steps > 0 && nsteps >= opt.max_steps)
        throw fail(fmt::format("too much work: max_steps = {} steps taken without reaching t_end = {}",
                               opt.max_steps, t_end),
                   "", tout);
      double tret = tn;
      const int flag = stepper->step(tout, y.get(), &tret);
      if (data.exception) std::rethrow_exception(data.exception);
      if (flag < 0) {
        const std::string fname = stepper->flag_name(flag);
        throw fail(describe_flag(fname), fmt::format("{}, flag {}", fname, flag), tout);
      }
      ++nsteps;
      if (tret == tn) {
        if (++stagnant >= kMaxStagnantSteps)
          throw fail(fmt::format("step size underflow: {} consecutive steps with t + h == t (the solution is "
                                 "singular or non-smooth here, or the tolerances cannot be met)",
                                 stagnant),
                     "", tout);
      } else {
        stagnant = 0;
      }
      tn = tret;
      if (events.active() && tn > t_before) {
        if (events.crossed(tn, ymap.data())) {
          const EventLocator::Root root = events.locate(t_before, tn, [&](double t, double* x) {
            dense(t, tout);
            std::copy(youtmap.data(), youtmap.data() + n, x);
          });
          emit_up_to_event(
              root.t, schedule, tout,
              [&](double t) {
                dense(t, t);
                return emit(t, youtmap);
              },
              [&] {
                youtmap = root.x;
                emit(root.t, youtmap);
              });
          stats.event = root.event;
          stats.t_event = root.t;
          stepper->fill_stats(stats);
          return stats;
        }
        events.reset(tn, ymap.data());
      }
    }
    if (tout == tn)
      youtmap = ymap;
    else
      dense(tout, tout);
    if (!emit(tout, youtmap)) break;
  }
  stepper->fill_stats(stats);
  return stats;
}

// ---- RK4 -------------------------------------------------------------------------

IntegratorStats integrate_rk4(const OdeProblem& problem, const IntegratorOptions& opt, double t0,
                              const Eigen::VectorXd& x0, double t_end, double dt_out, const OutputFn& output,
                              IntegratorStats stats, double grid_origin) {
  if (!(opt.h > 0) || !std::isfinite(opt.h))
    throw std::invalid_argument(fmt::format("rk4: step h must be positive and finite, got {}", opt.h));
  const int n = problem.n;
  const double h = opt.h;
  Eigen::VectorXd x = x0, xs(n), k1(n), k2(n), k3(n), k4(n), xo(n), x_next(n);
  double t = t0;  // time of the last accepted state x

  auto error = [&](const std::string& what) {
    return IntegrationError(fmt::format("rk4: integration failed at t = {}: {}", t, what), t, x);
  };
  auto eval = [&](double ts, const Eigen::VectorXd& xin, Eigen::VectorXd& out) {
    const int rc = problem.rhs(ts, xin.data(), out.data());
    ++stats.rhs_evals;
    if (rc != 0) throw error(fmt::format("rhs returned {} at t = {}", rc, ts));
    std::string bad = first_nonfinite(out.data(), n);
    if (!bad.empty()) throw error(fmt::format("rhs produced a non-finite derivative at t = {} ({})", ts, bad));
  };
  auto emit = [&]() {
    xo = x;
    if (problem.project) problem.project(xo.data());
    return output ? output(t, xo) : true;
  };

  if (!emit()) return stats;

  OutputSchedule schedule(t0, t_end, dt_out, grid_origin);
  EventLocator events(problem);
  events.reset(t0, x.data());
  // one RK4 step of size ts - t from the last accepted state: the interpolant inside a step
  // one classical RK4 step from (ta, xa) to ts: the method's step, and its interpolant inside a step
  Eigen::VectorXd xa(n);
  double ta = t0;
  auto step_to = [&](double ts, double* out) {
    const double hs = ts - ta;
    Eigen::Map<Eigen::VectorXd> o(out, n);
    if (hs == 0) {
      o = xa;
      return;
    }
    eval(ta, xa, k1);
    xs = xa + 0.5 * hs * k1;
    eval(ta + 0.5 * hs, xs, k2);
    xs = xa + 0.5 * hs * k2;
    eval(ta + 0.5 * hs, xs, k3);
    xs = xa + hs * k3;
    eval(ts, xs, k4);
    o = xa + (hs / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  };
  double tout = t0;
  while (schedule.next(tout)) {
    const double t_start = t;
    long j = 0;
    while (t < tout) {
      if (opt.max_steps > 0 && stats.steps >= opt.max_steps)
        throw error(fmt::format("too much work: max_steps = {} steps taken without reaching t_end = {}",
                                opt.max_steps, t_end));
      double t_next = t_start + static_cast<double>(j + 1) * h;
      if (t_next >= tout - 1e-8 * h) t_next = tout;  // shortened (or slightly stretched) last step
      xa = x;
      ta = t;
      step_to(t_next, x_next.data());
      xs = x_next;
      if (problem.project) problem.project(xs.data());
      std::string bad = first_nonfinite(xs.data(), n);
      if (!bad.empty())
        throw error(fmt::format("non-finite state after the step to t = {} ({})", t_next, bad));
      x = xs;
      t = t_next;
      ++j;
      ++stats.steps;
      if (events.active()) {
        if (events.crossed(t, x.data())) {
          const EventLocator::Root root = events.locate(ta, t, step_to);
          emit_up_to_event(
              root.t, schedule, tout,
              [&](double ts) {
                step_to(ts, xo.data());
                if (problem.project) problem.project(xo.data());
                return output ? output(ts, xo) : true;
              },
              [&] {
                x = root.x;
                t = root.t;
                if (problem.project) problem.project(x.data());
                emit();
              });
          stats.event = root.event;
          stats.t_event = root.t;
          return stats;
        }
        events.reset(t, x.data());
      }
    }
    if (!emit()) break;
  }
  return stats;
}

}  // namespace

IntegrationError::IntegrationError(const std::string& reason, double t, Eigen::VectorXd x)
    : std::runtime_error(fmt::format("{}; state = {}", reason, format_state(x))), t(t), x(std::move(x)),
      reason(reason) {}

// ---- public API ------------------------------------------------------------------

std::string to_string(IntegratorKind kind) {
  for (const auto& kn : kKindNames)
    if (kn.kind == kind) return kn.name;
  throw std::invalid_argument("invalid IntegratorKind");
}

std::vector<std::string> integrator_names() {
  std::vector<std::string> names;
  for (const auto& kn : kKindNames) names.emplace_back(kn.name);
  return names;
}

IntegratorKind integrator_from_string(const std::string& name) {
  for (const auto& kn : kKindNames)
    if (name == kn.name) return kn.kind;
  std::string list;
  for (const auto& kn : kKindNames) {
    if (!list.empty()) list += ", ";
    list += kn.name;
  }
  throw std::invalid_argument(fmt::format("unknown integrator '{}'; expected one of: {}", name, list));
}

std::string IntegratorStats::summary() const {
  return fmt::format("{}: {} steps, {} rhs evals, {} jac evals, {:.6f} s", integrator, steps, rhs_evals, jac_evals,
                     wall_seconds);
}

IntegratorStats integrate(const OdeProblem& problem, const IntegratorOptions& options, double t0,
                          const Eigen::VectorXd& x0, double t_end, double dt_out, const OutputFn& output,
                          double grid_origin) {
  if (problem.n < 0) throw std::invalid_argument(fmt::format("integrate: problem size n = {} is negative", problem.n));
  if (x0.size() != problem.n)
    throw std::invalid_argument(
        fmt::format("integrate: initial state has {} components, problem has n = {}", x0.size(), problem.n));
  if (!problem.rhs) throw std::invalid_argument("integrate: problem.rhs is not set");
  if (!std::isfinite(t0) || !std::isfinite(t_end) || t_end < t0)
    throw std::invalid_argument(fmt::format("integrate: need finite t0 <= t_end, got t0 = {}, t_end = {}", t0, t_end));
  if (!(dt_out > 0) || !std::isfinite(dt_out))
    throw std::invalid_argument(fmt::format("integrate: output interval dt_out must be positive, got {}", dt_out));
  if (!x0.allFinite()) throw std::invalid_argument("integrate: initial state is not finite: " + format_state(x0));

  const auto start = std::chrono::steady_clock::now();
  IntegratorStats stats;
  stats.integrator = to_string(options.kind);

  if (problem.n == 0) {
    // nothing to integrate (a model without degrees of freedom, e.g. only
    // prescribed motion): the (empty) state at every output time
    OutputSchedule schedule(t0, t_end, dt_out, grid_origin);
    const Eigen::VectorXd empty;
    if (!output || output(t0, empty))
      for (double t; t_end > t0 && schedule.next(t);)
        if (output && !output(t, empty)) break;
  } else if (t_end == t0) {
    Eigen::VectorXd xo = x0;
    if (problem.project) problem.project(xo.data());
    if (output) output(t0, xo);
  } else if (options.kind == IntegratorKind::automatic) {
    throw std::invalid_argument("integrate: 'auto' is resolved by the caller (choose_integrator, simulate.hpp)");
  } else if (options.kind == IntegratorKind::rk4) {
    stats = integrate_rk4(problem, options, t0, x0, t_end, dt_out, output, std::move(stats), grid_origin);
  } else if (options.kind == IntegratorKind::dopri5 || options.kind == IntegratorKind::rkf78) {
    stats = integrate_odeint(problem, options, t0, x0, t_end, dt_out, output, std::move(stats), grid_origin);
  } else {
    stats = integrate_sundials(problem, options, t0, x0, t_end, dt_out, output, std::move(stats), grid_origin);
  }
  stats.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace kanegen
