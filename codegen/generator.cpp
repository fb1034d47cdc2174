#include "codegen/generator.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "codegen/kane_context.hpp"
#include "codegen/joint_frames.hpp"
#include "codegen/merge_fixed.hpp"
#include "codegen/outlined_code.hpp"
#include "kanegen_generator_hash.h"
#include "model/model_hash.hpp"

#include "model/diagnostics.hpp"

namespace kanegen::codegen {

namespace {

constexpr const char* kIndent = "  ";

std::string body_comment(const Model& model, const Body& b) {
  const std::string parent = b.parent < 0 ? "ground" : model.bodies[b.parent].name;
  std::string s = fmt::format("// body {}: {} joint to {}", b.name, to_string(b.joint.type), parent);
  if (b.joint.node >= 0) s += fmt::format(" at node {}", model.bodies[b.parent].flex->nodes[b.joint.node].id);
  s += fmt::format(", mass {:.6g} kg", b.total_mass);
  // the file name only: the bytes must not depend on where the model was read from
  if (b.flex)
    s += fmt::format(", flexible: {} modes from {}", b.n_modes(),
                     std::filesystem::path(b.flex->source).filename().string());
  return s + "\n";
}

void finish_straight(const Program& p, EmittedFunction& f, const GeneratorOptions& options);

/// One function's Program, checked and printed into `f`.
void finish(const Program& p, const Constants& C, EmittedFunction& f, const GeneratorOptions& options) {
  const std::set<std::string> constants = C.names();
  for (const std::string& n : p.names())
    if (constants.count(n))
      throw std::logic_error(fmt::format("generator: temporary '{}' would shadow a model constant", n));
  f.body = p.emit(kIndent, f.ops);
  f.joint_sincos = p.has_sincos();
  if (f.name == "udot") f.ops_by_pass = p.ops_by_pass();
  const bool compact_wanted =
      options.udot_code == "compact" || (options.udot_code == "auto" && f.ops.total() > kCompactAboveOps);
  if (compact_wanted && f.templated && f.name == "udot") {
    OpCount ops;
    OutlinedBody o = outline(p, f.name, C, kIndent, ops);
    if (ops.total() != f.ops.total())
      throw std::logic_error(fmt::format("generator: {} outlined counts {} operations, straight-line {}", f.name,
                                         ops.total(), f.ops.total()));
    const bool shared = o.kernel_ops.total() <= kCompactShare * static_cast<double>(f.ops.total());
    if (options.udot_code == "auto" && !shared) return finish_straight(p, f, options);
    f.body = std::move(o.main);
    f.kernels = std::move(o.kernels);
    f.kernel_calls = o.calls;
    f.kernel_tables = std::move(o.tables);
    f.kernel_ops = o.kernel_ops;
    f.workspace = o.workspace;
    f.workspace_values = o.workspace_values;
    return;
  }
  finish_straight(p, f, options);
}

/// f as straight-line code, in parts when it is large (f.body already holds the one-piece code).
void finish_straight(const Program& p, EmittedFunction& f, const GeneratorOptions& options) {
  if (options.split_above > 0 && f.ops.total() > options.split_above && f.templated) {
    OpCount ops;
    ChunkedBody c = p.emit_chunked(kIndent, ops, options.part_ops);
    f.body = std::move(c.main);
    f.parts = std::move(c.parts);
    f.workspace = c.workspace;
  }
}

EmittedFunction function(std::string name, std::string title, std::vector<Arg> args, std::string out_name,
                         int out_size, bool returns_status = false) {
  EmittedFunction f;
  f.name = std::move(name);
  f.title = std::move(title);
  f.args = std::move(args);
  f.out_name = std::move(out_name);
  f.out_size = out_size;
  f.returns_status = returns_status;
  return f;
}

/// u_dot in the composite-inertia form (M by composite inertias, F by the
/// inward pass, L^T D L along the tree) or the articulated-body form.
std::vector<ex> compute_udot(KaneContext& ctx, const std::string& form, std::vector<ex>& pivots,
                             std::vector<ex>& scales) {
  if (form != "composite") return compute_udot_articulated(ctx, pivots, scales);
  const SMat M = compute_mass_matrix(ctx);  // M first: the order of the emitted code
  const std::vector<ex> F = compute_forcing(ctx);
  return solve_tree_ldlt(ctx, M, F, pivots, scales);
}

/// What the dual-number functions below share: the duals of every argument
/// at their values (seeded one direction per pass by the caller), and the
/// calls of qdot(), udot() and outputs() on them.
struct DualCalls {
  bool timed = false, inputs = false, params = false;
  std::string declarations() const {
    return "  using D = Dual<1>;\n"
           "  D qd[nq > 0 ? nq : 1], ud[nu > 0 ? nu : 1], td[nu > 0 ? nu : 1], wd[nw > 0 ? nw : 1];\n"
           "  for (int i = 0; i < nq; ++i) qd[i] = D(q[i]);\n"
           "  for (int i = 0; i < nu; ++i) { ud[i] = D(u[i]); td[i] = D(tau[i]); }\n" +
           std::string(inputs ? "  for (int i = 0; i < nw; ++i) wd[i] = D(inputs[i]);\n" : "");
  }
  /// The seed of direction c over [q; u; w; tau] set to `v`.
  static std::string seed(const char* c, const char* v) {
    return fmt::format(
        "    if ({0} < nq) qd[{0}].d[0] = {1}; else if ({0} < nq + nu) ud[{0} - nq].d[0] = {1}; "
        "else if ({0} < nq + nu + nw) wd[{0} - nq - nu].d[0] = {1}; else td[{0} - nq - nu - nw].d[0] = {1};\n",
        c, v);
  }
  std::string call(const std::string& f, const char* out, bool with_tau = true) const {
    return fmt::format("{}({}qd, ud, {}{}{}{})", f, timed ? "t, " : "", with_tau ? "td, " : "", inputs ? "wd, " : "",
                       params ? "prm, " : "", out);
  }
  std::vector<Arg> args() const {
    std::vector<Arg> a{Arg::q, Arg::u, Arg::tau};
    if (timed) a.insert(a.begin(), Arg::t);
    if (inputs) a.push_back(Arg::inputs);
    if (params) a.push_back(Arg::params);
    a.push_back(Arg::out);
    return a;
  }
};

/// The exact Jacobian of x_dot = [q_dot; u_dot] by forward-mode dual numbers
/// over qdot() and udot() (the Dual type is part of the header template).
EmittedFunction jacobian_function(int nq, int nu, const DualCalls& d, const OpCount& qdot_ops, const OpCount& udot_ops) {
  EmittedFunction f = function("jacobian", "Jacobian of x_dot = [q_dot; u_dot] w.r.t. x = [q; u], column-major",
                               d.args(), "J", (nq + nu) * (nq + nu), true);
  f.templated = false;
  f.note =
      "// Forward-mode differentiation of qdot() and udot() with dual numbers, one\n"
      "// direction per pass: exact to rounding. Returns like udot().\n";
  // One direction per pass: the code of each pass stays about twice the size of
  // u_dot itself, which keeps compile times low (8 directions per pass compiled
  // 5x slower for a 1.5x faster Jacobian).
  f.body = "  constexpr int nx = nq + nu;\n" + d.declarations() +
           "  D qdot_out[nq > 0 ? nq : 1], udot_out[nu > 0 ? nu : 1];\n"
           "  for (int c = 0; c < nx; ++c) {\n" +
           DualCalls::seed("c", "1.0") + "    qdot(qd, ud, qdot_out);\n" +
           "    const int status = " + d.call("udot", "udot_out") + ";\n" + DualCalls::seed("c", "0.0") +
           "    if (status != 0) return status;\n"
           "    for (int i = 0; i < nq; ++i) J[c * nx + i] = qdot_out[i].d[0];\n"
           "    for (int i = 0; i < nu; ++i) J[c * nx + nq + i] = udot_out[i].d[0];\n"
           "  }\n"
           "  return 0;\n";
  // A dual operation costs about three double ones; one pass per column.
  const long per_pass = 3 * (qdot_ops.total() + udot_ops.total());
  f.ops.mul = per_pass * (nq + nu);
  return f;
}

/// d(u_dot)/dw, nu x nw column-major: the input matrix of the linear model.
EmittedFunction input_jacobian_function(int nq, int nu, int nw, const DualCalls& d, const OpCount& udot_ops) {
  EmittedFunction f = function("input_jacobian", "d(u_dot)/dw w.r.t. the named inputs, column-major nu x nw",
                               d.args(), "B", nu * nw, true);
  f.templated = false;
  f.note = "// Forward-mode dual numbers, one input per pass. Returns like udot().\n";
  f.body = d.declarations() + "  D udot_out[nu > 0 ? nu : 1];\n  for (int c = nq + nu; c < nq + nu + nw; ++c) {\n" +
           DualCalls::seed("c", "1.0") + "    const int status = " + d.call("udot", "udot_out") + ";\n" +
           DualCalls::seed("c", "0.0") +
           "    if (status != 0) return status;\n"
           "    for (int i = 0; i < nu; ++i) B[(c - nq - nu) * nu + i] = udot_out[i].d[0];\n"
           "  }\n"
           "  return 0;\n";
  f.ops.mul = 3 * udot_ops.total() * nw;
  (void)nq;
  return f;
}

/// dy/d[q; u; w; tau], ny x (nq + 2 nu + nw) column-major: the output matrices C, D.
EmittedFunction output_jacobian_function(int nq, int nu, int nw, int ny, const DualCalls& d, const OpCount& y_ops) {
  EmittedFunction f = function("output_jacobian", "dy/d[q; u; w; tau] of the named outputs, column-major",
                               d.args(), "CD", ny * (nq + 2 * nu + nw));
  f.templated = false;
  f.note = "// Forward-mode dual numbers, one direction per pass.\n";
  f.body = d.declarations() + "  D y_out[ny > 0 ? ny : 1];\n  for (int c = 0; c < nq + 2 * nu + nw; ++c) {\n" +
           DualCalls::seed("c", "1.0") + "    " + d.call("outputs", "y_out") + ";\n" + DualCalls::seed("c", "0.0") +
           "    for (int i = 0; i < ny; ++i) CD[c * ny + i] = y_out[i].d[0];\n"
           "  }\n";
  f.ops.mul = 3 * y_ops.total() * (nq + 2 * nu + nw);
  return f;
}

/// The prescribed-motion functions of time the emitted code calls (the same
/// formulas as model/prescribed_motion.cpp, which the generic engine uses).
std::string motion_support_code() {
  return R"(
// ---- prescribed motion: f(t), f'(t), f''(t) of a joint coordinate ------------
inline void motion_polynomial(double t, const double* c, int n, double& f, double& fd, double& fdd) {
  f = fd = fdd = 0.0;
  for (int i = n - 1; i >= 0; --i) {
    fdd = fdd * t + 2.0 * fd;
    fd = fd * t + f;
    f = f * t + c[i];
  }
}
inline void motion_sine(double t, double offset, double amplitude, double frequency_hz, double phase, double& f,
                        double& fd, double& fdd) {
  const double w = 6.283185307179586476925 * frequency_hz, a = w * t + phase;
  f = offset + amplitude * std::sin(a);
  fd = amplitude * w * std::cos(a);
  fdd = -amplitude * w * w * std::sin(a);
}
// The smooth spin-up of Kane, Ryan and Banerjee (1987) to `rate` over `duration`.
inline void motion_spinup(double t, double rate, double duration, double start, double& f, double& fd,
                          double& fdd) {
  constexpr double two_pi = 6.283185307179586476925;
  if (t < 0.0) {
    f = start, fd = 0.0, fdd = 0.0;
  } else if (t < duration) {
    const double a = two_pi * t / duration;
    f = start + rate * (t * t / (2.0 * duration) + (duration / (two_pi * two_pi)) * (std::cos(a) - 1.0));
    fd = (rate / duration) * (t - (duration / two_pi) * std::sin(a));
    fdd = (rate / duration) * (1.0 - std::cos(a));
  } else {
    f = start + rate * (t - duration / 2.0), fd = rate, fdd = 0.0;
  }
}
)";
}

}  // namespace

const char* generator_hash() { return KANEGEN_GENERATOR_HASH; }

std::string generator_identity(const GeneratorOptions& options) {
  return std::string(generator_hash()) + (options.udot_form == "auto" ? "" : "-" + options.udot_form) +
         (options.merge_fixed ? "" : "-unmerged") + (options.joint_frames ? "" : "-model-frames") +
         (options.split_above == GeneratorOptions{}.split_above && options.part_ops == GeneratorOptions{}.part_ops
              ? ""
              : fmt::format("-split{}-{}", options.split_above, options.part_ops)) +
         (options.udot_code == "auto" ? "" : "-" + options.udot_code);
}

const EmittedFunction* EmittedModel::find(const std::string& name) const {
  for (const auto& f : functions)
    if (f.name == name) return &f;
  return nullptr;
}

EmittedModel generate(const Model& model_in, const GeneratorOptions& options) {
  if (options.udot_form != "auto" && options.udot_form != "composite" && options.udot_form != "articulated")
    throw std::invalid_argument("udot form must be auto, composite or articulated");
  // Central gravity acts on each rigid part (dynamics.md): a body fixed to its parent keeps its own
  // MacCullagh term, so the tree is not merged (the merged part's term differs at O(size/r)^3).
  const Model merged = options.merge_fixed && !model_in.central ? merge_fixed_bodies(model_in) : model_in;
  auto frames = [&](const Model& m) { return options.joint_frames ? choose_joint_frames(m) : keep_joint_frames(m); };
  const FramedModel framed = frames(merged);
  const Model& dyn = framed.model;  // used for M, F, u_dot, energy, momentum
  Constants C;
  const StateSymbols x(dyn);
  EmittedModel out;
  out.model_name = model_in.name;
  out.identifier = cpp_identifier(model_in.name);
  out.description = model_in.description;
  out.model_hash = model_hash(model_in);
  out.generator_hash = generator_identity(options);
  out.nq = model_in.nq;
  out.nu = model_in.nu;
  out.nbodies = static_cast<int>(model_in.bodies.size());
  out.q_names = model_in.q_names;
  out.u_names = model_in.u_names;
  out.nw = model_in.nw;
  out.ny = model_in.ny;
  out.input_names = model_in.input_names;
  out.output_names = model_in.output_names;
  out.np = static_cast<int>(model_in.parameters.size());
  for (const RuntimeParameter& p : model_in.parameters) {
    out.parameter_names.push_back(p.name);
    out.parameter_units.push_back(p.unit);
    out.parameter_nominal.push_back(p.nominal);
  }
  auto& fns = out.functions;
  // Functions take t only when the scene has prescribed motion.
  const bool timed = dyn.has_prescribed();
  // ... and the runtime parameters only when the model declares some (all but qdot)
  const bool has_params = !model_in.parameters.empty();
  auto at_t = [timed, has_params](std::vector<Arg> args) {
    if (timed) args.insert(args.begin(), Arg::t);
    if (has_params) args.insert(args.end() - 1, Arg::params);
    return args;
  };
  if (timed) out.support_code = motion_support_code();
  // Functions of the forces take the named inputs only when the model declares some.
  const bool has_inputs = dyn.nw > 0;
  auto forced = [&](std::vector<Arg> args) {
    if (has_inputs) args.insert(args.end() - 1, Arg::inputs);
    return at_t(std::move(args));
  };
  const bool attitude = std::any_of(model_in.sensors.begin(), model_in.sensors.end(), [](const Sensor& s) {
    return s.type == SensorType::attitude || s.type == SensorType::attitude_lvlh;
  });
  if (attitude) out.support_code += attitude_support_code();
  out.orbit_frame_rules = std::any_of(model_in.sensors.begin(), model_in.sensors.end(),
                                      [](const Sensor& s) { return orbit_sensor(s.type); });
  if (out.orbit_frame_rules) out.support_code += orbit_frame_support_code();

  {
    Program p;
    KaneContext ctx(framed, p, C, x);
    const auto qd = compute_qdot(ctx);
    for (int i = 0; i < dyn.nq; ++i) p.assign(fmt::format("qdot[{}]", i), qd[i]);
    EmittedFunction f = function("qdot", "q_dot = W(q) u", {Arg::q, Arg::u, Arg::out}, "qdot", dyn.nq);
    finish(p, C, f, options);
    fns.push_back(std::move(f));
  }
  {
    Program p;
    KaneContext ctx(framed, p, C, x);
    prepare(ctx, false);
    const SMat M = compute_mass_matrix(ctx);
    for (int r = 0; r < dyn.nu; ++r)
      for (int c = 0; c < dyn.nu; ++c) p.assign(fmt::format("M[{}]", r * dyn.nu + c), M(r, c));
    EmittedFunction f = function("mass_matrix", "M(q), row-major", at_t({Arg::q, Arg::out}), "M", dyn.nu * dyn.nu);
    finish(p, C, f, options);
    fns.push_back(std::move(f));
  }
  {
    Program p;
    KaneContext ctx(framed, p, C, x);
    prepare(ctx, true);
    const auto F = compute_forcing(ctx);
    for (int r = 0; r < dyn.nu; ++r) p.assign(fmt::format("F[{}]", r), F[r]);
    EmittedFunction f = function("forcing", "F(q, u, tau)", forced({Arg::q, Arg::u, Arg::tau, Arg::out}), "F", dyn.nu);
    finish(p, C, f, options);
    fns.push_back(std::move(f));
  }
  // u_dot: the composite-inertia form (M by composite inertias, F by the
  // inward pass, L^T D L along the tree; O(n^2) plus O(n d^2)) or the
  // articulated-body form (O(n)), whichever takes fewer operations here.
  EmittedFunction udot;
  for (const char* form : {"composite", "articulated"}) {
    Program p;
    KaneContext ctx(framed, p, C, x);
    prepare(ctx, true);
    std::vector<ex> pivots, scales;
    const std::vector<ex> ud = compute_udot(ctx, form, pivots, scales);
    OpCount dummy;
    for (std::size_t r = 0; r < pivots.size(); ++r) {
      if (GiNaC::is_a<GiNaC::numeric>(pivots[r]) && GiNaC::ex_to<GiNaC::numeric>(pivots[r]).is_positive()) continue;
      const bool scaled = r < scales.size() && !(scales[r] - pivots[r]).is_zero();
      const std::string test = scaled ? fmt::format("{} > {}*{}", print_cpp(pivots[r], dummy), kPivotRatio,
                                                    print_cpp(scales[r], dummy))
                                      : fmt::format("{} > 0.0", print_cpp(pivots[r], dummy));
      p.statement(fmt::format("if (!({})) return {};", test, r + 1), scaled ? pivots[r] + scales[r] : pivots[r]);
    }
    for (int r = 0; r < dyn.nu; ++r) p.assign(fmt::format("udot[{}]", r), ud[r]);
    EmittedFunction f = function("udot",
                                 "u_dot: M u_dot = F (form chosen by operation count, see the counts above)",
                                 forced({Arg::q, Arg::u, Arg::tau, Arg::out}), "udot", dyn.nu, true);
    f.note = "// Returns 0, or k if the pivot of speed k (1-based) is not positive (M singular).\n";
    finish(p, C, f, options);
    (std::string(form) == "composite" ? out.udot_composite_ops : out.udot_articulated_ops) = f.ops;
    const bool forced = options.udot_form == form;
    const bool chosen_forced = options.udot_form != "auto" && !udot.name.empty();
    if (forced || (!chosen_forced && (udot.name.empty() || f.ops.total() < udot.ops.total()))) {
      udot = std::move(f);
      out.udot_form = form;
    }
  }
  const OpCount udot_ops = udot.ops, qdot_ops = fns.front().ops;
  fns.push_back(std::move(udot));

  const auto& outs = model_in.outputs;
  if (outs.energy) {
    Program p;
    KaneContext ctx(framed, p, C, x);
    prepare(ctx, true);
    p.assign("TV[0]", compute_kinetic_energy(ctx));
    p.assign("TV[1]", compute_potential_energy(ctx));
    EmittedFunction f = function("energy", "energy: T, V", at_t({Arg::q, Arg::u, Arg::out}), "TV", 2);
    finish(p, C, f, options);
    fns.push_back(std::move(f));
  }
  if (outs.momentum) {
    Program p;
    KaneContext ctx(framed, p, C, x);
    prepare(ctx, true);
    const auto pH = compute_momentum(ctx);
    for (int i = 0; i < 6; ++i) p.assign(fmt::format("pH[{}]", i), pH[i]);
    EmittedFunction f =
        function("momentum", "momentum: p_N[3], H_N[3] about N's origin", at_t({Arg::q, Arg::u, Arg::out}), "pH", 6);
    finish(p, C, f, options);
    fns.push_back(std::move(f));
  }
  if (outs.reactions) {  // on the unmerged tree: every body, fixed ones included
    const FramedModel fr = frames(model_in);
    const StateSymbols xr(fr.model);
    Program p;
    KaneContext ctx(fr, p, C, xr);
    prepare(ctx, true);
    const auto W = compute_reactions(ctx, xr.udot);
    // back to the model's body axes and origin: [R_BB' f; R_BB' t + o_B x R_BB' f]
    for (int j = 0; j < out.nbodies; ++j) {
      const std::string& n = fr.model.bodies[j].name;
      const SM3 Q = ctx.cmat(fr.R_BBp[j], n + "_R_BBp", "", "the model's body axes from the generator's (joint_frames.hpp)");
      const SV3 f = ctx.A.mul(Q, SV3{{W[6 * j], W[6 * j + 1], W[6 * j + 2]}});
      SV3 t = ctx.A.mul(Q, SV3{{W[6 * j + 3], W[6 * j + 4], W[6 * j + 5]}});
      if (!fr.o_B[j].isZero(0.0))
        t = ctx.A.add(t, ctx.A.cross(ctx.cvec(fr.o_B[j], n + "_o_B", "m", "the generator's origin from the model's"), f));
      for (int a = 0; a < 3; ++a) {
        p.assign(fmt::format("wrenches[{}]", 6 * j + a), f[a]);
        p.assign(fmt::format("wrenches[{}]", 6 * j + 3 + a), t[a]);
      }
    }
    EmittedFunction f =
        function("reactions", "reactions on each body from its parent: [force; torque about O_B], body axes",
                 forced({Arg::q, Arg::u, Arg::udot_in, Arg::out}), "wrenches", 6 * out.nbodies);
    finish(p, C, f, options);
    fns.push_back(std::move(f));
  }
  const DualCalls dual{timed, has_inputs, has_params};
  fns.push_back(jacobian_function(dyn.nq, dyn.nu, dual, qdot_ops, udot_ops));
  if (has_inputs) fns.push_back(input_jacobian_function(dyn.nq, dyn.nu, dyn.nw, dual, udot_ops));
  if (model_in.ny > 0) {
    // On the unmerged tree (reactions of fixed bodies), sharing the kinematics,
    // u_dot and the reactions' accelerations with the dynamics.
    const FramedModel fr = frames(model_in);
    const StateSymbols xr(fr.model);
    Program p;
    KaneContext ctx(fr, p, C, xr);
    prepare(ctx, true);
    std::vector<ex> pivots, scales;
    const std::vector<ex> ud = compute_udot(ctx, out.udot_form, pivots, scales);
    std::vector<std::vector<ex>> acc;
    const auto W = compute_reactions(ctx, ud, &acc);
    assign_sensor_outputs(ctx, W, acc, "y");
    EmittedFunction f = function("outputs", "named outputs y (sensors)",
                                 forced({Arg::q, Arg::u, Arg::tau, Arg::out}), "y", model_in.ny);
    finish(p, C, f, options);
    const OpCount y_ops = f.ops;
    fns.push_back(std::move(f));
    fns.push_back(output_jacobian_function(dyn.nq, dyn.nu, dyn.nw, model_in.ny, dual, y_ops));
  }

  // Constants, grouped per body with a comment block.
  for (const std::string& g : C.groups()) {
    const int bi = model_in.body_index(g);
    out.constants += bi >= 0                 ? body_comment(model_in, model_in.bodies[bi])
                     : g == kDerivedGroup ? std::string("// derived: constant subexpressions, evaluated here exactly\n")
                                          : std::string("// model\n");
    out.constants += C.emit(g, "") + "\n";
  }
  return out;
}

}  // namespace kanegen::codegen
