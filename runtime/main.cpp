// kanegen: the command-line interface (interface.md).
// Exit status: 0 success, 2 refused input (message names file, line, field),
// 1 failure while running.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "crosscheck.hpp"
#include "diagnostics.hpp"
#include "eval_report.hpp"
#include "generate.hpp"
#include "generic_engine.hpp"
#include "integrators.hpp"
#include "jit.hpp"
#include "model_checks.hpp"
#include "modal_data.hpp"
#include "model_loader.hpp"
#include "simulate.hpp"
#include "state_io.hpp"
#include "work_precision.hpp"

using namespace kanegen;

namespace {

constexpr int kExitFailure = 1;
constexpr int kExitRefused = 2;

struct Args {
  std::string model, state, engine = "generated", output, integrator = "cvode-bdf", body;
  std::string form = "auto";
  std::string depfile;
  double t_end = 10.0, rtol = 1e-8, atol = 1e-10, dt_out = 0.01, h = 1e-3;
  bool no_progress = false;
  int samples = 20;
  unsigned seed = 1;
};

Model load_checked(const std::string& path) {
  Model model = load_model(path);
  check_mass_matrix_at_initial_state(model);
  return model;
}

std::unique_ptr<Engine> make_engine(const Model& model, const std::string& name) {
  if (name == "generic") return std::make_unique<GenericEngine>(model);
  if (name == "generated") {
    try {
      return jit_load(model);
    } catch (const JitError& e) {  // the generated code of this model does not compile
      throw InputError(Diagnostic{model.source_path, 0, "", e.what()});
    }
  }
  throw InputError(
      Diagnostic{"--engine", 0, "", fmt::format("unknown engine '{}'; expected generated or generic", name)});
}

State state_for(const Model& model, const std::string& state_path) {
  return state_path.empty() ? initial_state(model) : load_state(model, state_path);
}

int cmd_check(const Args& a) {
  const Model model = load_checked(a.model);
  fmt::print("model {}: {} bodies, nq = {}, nu = {}\n", model.name, model.bodies.size(), model.nq, model.nu);
  if (!model.description.empty()) fmt::print("  {}\n", model.description);
  for (const Body& b : model.bodies) {
    std::string parent = b.parent < 0 ? "ground" : model.bodies[b.parent].name;
    if (b.joint.node >= 0) parent += fmt::format(" @node {}", model.bodies[b.parent].flex->nodes[b.joint.node].id);
    fmt::print("  {:<16} {:<9} joint to {:<16} mass {:.6g} kg", b.name, to_string(b.joint.type), parent,
               b.integrals.mass);
    if (b.flex) {
      fmt::print(", flexible: {} modes, {} nodes ({})", b.n_modes(), b.flex->nodes.size(), b.flex->source);
      for (int k = 0; k < b.n_modes(); ++k)
        fmt::print("\n    mode {}: {:.6g} Hz, damping ratio {:.3g}", k + 1, b.flex->frequency_hz(k),
                   b.flex->damping_ratio(k));
    }
    fmt::print("\n");
  }
  std::string dofs;
  for (const auto& n : model.u_names) dofs += (dofs.empty() ? "" : ", ") + n;
  fmt::print("  speeds: {}\n", dofs);
  return 0;
}

int cmd_generate(const Args& a) {
  const Model model = load_checked(a.model);
  gen::GeneratorOptions opt;
  opt.udot_form = a.form;
  const gen::GeneratedCode code = gen::generate(model, opt);
  // Written beside the target and renamed: never a half-written header.
  const std::string tmp = a.output + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!(out << code.header)) throw std::runtime_error("cannot write " + tmp);
  }
  std::filesystem::rename(tmp, a.output);
  if (!a.depfile.empty()) {  // Make-style: the header depends on the model and its modal files
    std::string deps = a.output + ":";
    auto add = [&](const std::string& f) {
      std::string e;
      for (char c : std::filesystem::absolute(f).string()) e += (c == ' ' ? std::string("\\ ") : std::string(1, c));
      deps += " " + e;
    };
    add(model.source_path);
    for (const Body& b : model.bodies)
      if (b.flex && b.flex->source != "beam") add(b.flex->source);
    std::ofstream(a.depfile) << deps << "\n";
  }
  fmt::print(stderr, "{}: u_dot {} operations ({} form), M {}, F {}\n", a.output, code.ops.at("udot").total(),
             code.udot_form,
             code.ops.at("mass_matrix").total(), code.ops.at("forcing").total());
  return 0;
}

int cmd_modes(const Args& a) {
  const Model model = load_model(a.model);
  const int i = model.body_index(a.body);
  if (i < 0 || !model.bodies[i].flex)
    throw InputError(Diagnostic{a.model, 0, "--body",
                                fmt::format("'{}' is not a flexible body of model {}", a.body, model.name)});
  const FlexibleData& f = *model.bodies[i].flex;
  write_modal_file(f, a.output);
  fmt::print("{}: {} nodes, {} modes of body {} ({})\n", a.output, f.nodes.size(), f.modes(), a.body, f.source);
  for (int k = 0; k < f.modes(); ++k) fmt::print("  mode {}: {:.6g} Hz\n", k + 1, f.frequency_hz(k));
  return 0;
}

int cmd_crosscheck(const Args& a) {
  const Model model = load_checked(a.model);
  auto generated = make_engine(model, "generated");
  GenericEngine generic(model);
  const CrosscheckResult r = crosscheck(*generated, generic, a.samples, a.seed);
  fmt::print("crosscheck {}: generated vs generic at {} random states (seed {})\n", model.name, r.samples, a.seed);
  for (const auto& [q, v] : r.worst) {
    const double tol = CrosscheckResult::tolerance(q);
    fmt::print("  {:<18} {:.3e}   {}\n", q, v, tol > 1 ? "(not judged: grows with cond(M))" : fmt::format("tolerance {:.0e}{}", tol, v <= tol ? "" : "  FAILED"));
  }
  fmt::print("{}\n", r.passed() ? "passed" : "FAILED");
  return r.passed() ? 0 : kExitFailure;
}

int cmd_eval(const Args& a) {
  const Model model = load_checked(a.model);
  const State state = state_for(model, a.state);
  auto engine = make_engine(model, a.engine);
  nlohmann::ordered_json j;
  try {
    j = eval_report(*engine, state);
  } catch (const SingularMassMatrix& e) {
    throw InputError(Diagnostic{a.state.empty() ? a.model : a.state, 0, "q", e.what()});
  }
  std::cout << j.dump(1) << '\n';
  return 0;
}

int cmd_simulate(const Args& a) {
  const Model model = load_checked(a.model);
  const State state = state_for(model, a.state);
  auto engine = make_engine(model, a.engine);
  SimulationOptions opt;
  opt.t_end = a.t_end;
  opt.dt_out = a.dt_out;
  try {
    opt.integrator.kind = integrator_from_string(a.integrator);
  } catch (const std::invalid_argument& e) {
    throw InputError(Diagnostic{"--integrator", 0, "", e.what()});
  }
  opt.integrator.rtol = a.rtol;
  opt.integrator.atol = a.atol;
  opt.integrator.h = a.h;
  opt.progress = !a.no_progress;
  if (!(a.t_end > state.t)) throw InputError(Diagnostic{"--t-end", 0, "", "must be after the initial time"});
  if (!(a.dt_out > 0)) throw InputError(Diagnostic{"--dt-out", 0, "", "must be positive"});
  try {
    const SimulationResult r = simulate_to_file(*engine, state, opt, a.output);
    fmt::print(stderr, "{} [{} engine], {} rows to {}, max quaternion drift {:.2e}\n", r.stats.summary(),
               engine->name(), r.rows, a.output, r.max_quaternion_drift);
  } catch (const IntegrationError& e) {
    std::string where;
    const int n = std::min<int>(static_cast<int>(e.x.size()), model.nq + model.nu);
    for (int i = 0; i < n; ++i)
      where += i < model.nq ? fmt::format("\n  q {} = {:.17g}", model.q_names[i], e.x(i))
                            : fmt::format("\n  u {} = {:.17g}", model.u_names[i - model.nq], e.x(i));
    fmt::print(stderr, "kanegen simulate: integration failed at t = {:.17g}: {}\nstate there:{}\nno output written\n",
               e.t, e.what(), where);
    return kExitFailure;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"kanegen: Kane's-method equations of motion for multibody spacecraft"};
  app.require_subcommand(1);
  Args a;
  auto add_model = [&](CLI::App* c) {
    c->add_option("MODEL", a.model, "model file (YAML, model-format.md)")->required()->check(CLI::ExistingFile);
  };
  auto add_engine = [&](CLI::App* c) {
    c->add_option("--engine", a.engine,
                  "generated: the model's generated code (JIT-compiled, cached); generic: the numeric path")
        ->check(CLI::IsMember({"generated", "generic"}))
        ->capture_default_str();
  };

  CLI::App* check = app.add_subcommand("check", "validate a model; print bodies, joints, dofs, modes");
  add_model(check);

  CLI::App* generate = app.add_subcommand("generate", "write the specialized C++ header of a model");
  add_model(generate);
  generate->add_option("-o,--output", a.output, "output header (.hpp)")->required();
  generate->add_option("--depfile", a.depfile, "also write a Make-style dependency file (model and modal files)");
  generate->add_option("--udot-form", a.form, "auto (fewer operations) | composite (M, F, tree LTDL) | articulated (O(n))")
      ->check(CLI::IsMember({"auto", "composite", "articulated"}))
      ->capture_default_str();

  CLI::App* modes = app.add_subcommand("modes", "write a flexible body's modes (e.g. of a built-in beam) as a modal file");
  add_model(modes);
  modes->add_option("--body", a.body, "flexible body")->required();
  modes->add_option("-o,--output", a.output, "output *.modal.yaml")->required();

  CLI::App* cross = app.add_subcommand("crosscheck", "compare generated and generic engines at random states");
  add_model(cross);
  cross->add_option("--samples", a.samples, "number of random states")->capture_default_str()->check(CLI::PositiveNumber);
  cross->add_option("--seed", a.seed, "random seed")->capture_default_str();

  CLI::App* eval = app.add_subcommand("eval", "evaluate M, F, u-dot (and the requested outputs) at one state, as JSON");
  add_model(eval);
  eval->add_option("--state", a.state, "STATE.json (default: the model's initial state)")
      ->check(CLI::ExistingFile);
  add_engine(eval);

  CLI::App* sim = app.add_subcommand("simulate", "integrate the equations of motion and write a CSV time history");
  add_model(sim);
  sim->add_option("--t-end", a.t_end, "final time [s]")->required();
  sim->add_option("-o,--output", a.output, "output CSV file")->required();
  sim->add_option("--state", a.state, "initial STATE.json (default: the model's initial state)")
      ->check(CLI::ExistingFile);
  add_engine(sim);
  sim->add_option("--integrator", a.integrator, "cvode-bdf | cvode-bdf2 (BDF capped at order 2, for lightly damped stiff modes) | cvode-adams | arkode-erk | arkode-dirk | rk4")
      ->capture_default_str();
  sim->add_option("--rtol", a.rtol, "relative tolerance (adaptive integrators)")->capture_default_str();
  sim->add_option("--atol", a.atol, "absolute tolerance (adaptive integrators)")->capture_default_str();
  sim->add_option("--dt-out", a.dt_out, "output interval [s]")->capture_default_str();
  sim->add_option("--h", a.h, "fixed step of rk4 [s]")->capture_default_str();
  sim->add_flag("--no-progress", a.no_progress, "no progress bar on stderr");

  bench::BenchOptions bench_opt;
  std::vector<std::string> bench_models;
  std::string bench_suite;
  CLI::App* bench_cmd = app.add_subcommand("bench", "work-precision: error against wall time for models x engines x integrators");
  bench_cmd->add_option("MODEL", bench_models, "model files (YAML)")->check(CLI::ExistingFile);
  bench_cmd->add_option("--engines", bench_opt.engines, "engines to compare")->delimiter(',')->capture_default_str();
  bench_cmd->add_option("--integrators", bench_opt.integrators,
                        "integrators (cvode-bdf-fd: BDF with finite-difference Jacobian)")->delimiter(',')->capture_default_str();
  bench_cmd->add_option("--tolerances", bench_opt.tolerances, "rtol sweep (atol = 1e-2 rtol) [1e-4,1e-6,1e-8,1e-10]")->delimiter(',');
  bench_cmd->add_option("--rk4-steps", bench_opt.rk4_steps, "rk4 step sizes [s] (default: 64,16,4,1 x the reference's mean step)")->delimiter(',');
  bench_cmd->add_option("--t-end", bench_opt.t_end, "simulated time [s] (default: from the model's comments, 'bench: t_end = T', else 10)");
  bench_cmd->add_option("--repeats", bench_opt.repeats, "timed runs per point (median)")->capture_default_str();
  bench_cmd->add_option("--max-run-seconds", bench_opt.max_run_seconds, "time budget of one run")->capture_default_str();
  bench_cmd->add_option("--out", bench_opt.out_dir, "output directory")->capture_default_str();
  bench_cmd->add_option("--suite", bench_suite, "extreme: also models/extreme/*.yaml");
  bench_cmd->add_flag("--quick", bench_opt.quick, "2 tolerances, 2 rk4 steps, 1 repeat");
  bench_cmd->add_flag("!--no-plot", bench_opt.plot, "skip the PNGs");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitRefused;
  }
  try {
    if (*check) return cmd_check(a);
    if (*generate) return cmd_generate(a);
    if (*modes) return cmd_modes(a);
    if (*cross) return cmd_crosscheck(a);
    if (*eval) return cmd_eval(a);
    if (*sim) return cmd_simulate(a);
    if (*bench_cmd) return bench::run_bench(bench_models, bench_opt, bench_suite);
  } catch (const InputError& e) {
    for (const Diagnostic& d : e.diagnostics()) fmt::print(stderr, "{}\n", d.str());
    return kExitRefused;
  } catch (const std::exception& e) {
    fmt::print(stderr, "kanegen: {}\n", e.what());
    return kExitFailure;
  }
  return kExitFailure;
}
