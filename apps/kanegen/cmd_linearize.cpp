// kanegen linearize MODEL [--state S.json] [--inputs ...] [--outputs ...]
//     [--format json|npz|mat|csv] [-o OUT]: the continuous-time linear model
// A, B, C, D about a state (sim/linearize.hpp), with its eigenvalues as
// frequencies and damping ratios (a table on stderr, and in the JSON).
#include <fmt/format.h>

#include <algorithm>

#include <iostream>

#include "apps/kanegen/cli_common.hpp"
#include "model/diagnostics.hpp"
#include "model/model_files.hpp"
#include "model/output_file.hpp"
#include "sim/linearize.hpp"
#include "sim/matrix_files.hpp"

namespace kanegen::cli {

namespace linearize_command {

struct Options {
  std::string model, state, engine = "generated", format = "json", output, frame = "inertial";
  std::vector<std::string> inputs, outputs;
  bool native = false, finite_differences = false, quiet = false, drop_ignorable = false;
  CLI::Option* output_option = nullptr;  ///< to tell -o "" (refused) from no -o (JSON on stdout)
};

void print_modes(const LinearModel& lin, const std::vector<LinearMode>& modes) {
  fmt::print(stderr, "linear model: {} states, {} inputs, {} outputs ({})\n", lin.A.rows(), lin.B.cols(),
             lin.C.rows(), lin.method);
  if (lin.equilibrium)
    fmt::print(stderr, "the point is an equilibrium{}\n",
               lin.ignorable_dropped ? " of the states left without the ignorable coordinates" : "");
  else if (lin.relative_equilibrium)
    fmt::print(stderr, "the point is a relative equilibrium: steady except for the ignorable coordinates, which "
                       "nothing else depends on ({}); --drop-ignorable leaves them out\n",
               fmt::join(lin.ignorable, ", "));
  else
    fmt::print(stderr, "the point is NOT an equilibrium (max |x_dot| = {:.3g}): the result is a first-order Taylor "
                       "model about it\n", lin.residual);
  if (!lin.ignorable.empty() && (lin.equilibrium || !lin.relative_equilibrium)) {
    if (lin.ignorable_dropped) {
      std::vector<std::string> left_out;
      for (const auto& n : lin.ignorable)
        if (std::find(lin.ignorable_kept_for_outputs.begin(), lin.ignorable_kept_for_outputs.end(), n) ==
            lin.ignorable_kept_for_outputs.end())
          left_out.push_back(n);
      fmt::print(stderr, "ignorable coordinates left out: {}\n", fmt::join(left_out, ", "));
    } else {
      fmt::print(stderr, "ignorable coordinates: {}\n", fmt::join(lin.ignorable, ", "));
    }
  }
  if (!lin.ignorable_kept_for_outputs.empty())
    fmt::print(stderr, "ignorable but kept, since outputs read them: {}\n",
               fmt::join(lin.ignorable_kept_for_outputs, ", "));
  fmt::print(stderr, "zero modes: |eigenvalue| <= {:.2g} (rigid-body or ignorable, or slower than that)\n",
             zero_mode_tolerance(lin));
  fmt::print(stderr, "{:>24} {:>24} {:>12} {:>10}  {}\n", "eigenvalue (1/s)", "", "f_n (Hz)", "zeta",
             "dominant states");
  for (const LinearMode& m : modes)
    if (m.zero)
      fmt::print(stderr, "{:>24} {:>24} {:>12} {:>10}  rigid-body / ignorable: {}\n", "0", "", "0", "-",
                 fmt::join(m.dominant_states, ", "));
    else
      fmt::print(stderr, "{:>24.10g} {:>+23.10g}i {:>12.6g} {:>10.4g}  {}\n", m.eigenvalue.real(), m.eigenvalue.imag(),
                 m.natural_frequency_hz, m.damping_ratio, fmt::join(m.dominant_states, ", "));
}

int run(const Options& o) {
  const Model model = load_checked(o.model);
  const State state = state_for(model, o.state);
  const bool to_file = o.output_option->count() > 0;
  if (o.format != "json" && !to_file)
    throw InputError(Diagnostic{"(command line)", 0, "--format",
                                fmt::format("--format {} writes a file; expected -o OUT as well", o.format)});
  if (to_file) check_output_options({{"-o", o.output}}, input_files(model, o.state));
  auto engine = make_engine(model, o.engine, o.native);
  LinearizeOptions lo;
  lo.inputs = o.inputs;
  lo.outputs = o.outputs;
  lo.finite_differences = o.finite_differences;
  lo.drop_ignorable = o.drop_ignorable;
  lo.frame = o.frame;
  const LinearModel lin = linearize(*engine, state, lo);
  const auto modes = linear_modes(lin);
  if (!o.quiet) print_modes(lin, modes);
  if (o.format == "json") {
    const std::string text = to_json(lin, modes).dump(1) + "\n";
    if (o.output.empty())
      std::cout << text;
    else
      write_file_atomically(o.output, text);
    return 0;
  }
  NamedMatrices nm;
  nm.matrices = {{"A", lin.A}, {"B", lin.B}, {"C", lin.C}, {"D", lin.D}, {"x0_dot", lin.x0_dot}, {"y0", lin.y0}};
  nm.names = {{"state_names", lin.state_names}, {"input_names", lin.input_names}, {"output_names", lin.output_names}};
  if (o.format == "npz")
    write_npz(o.output, nm);
  else if (o.format == "mat")
    write_mat(o.output, nm);
  else
    for (const auto& p : write_csv(o.output, nm,
                                   {{"A", {"state_names", "state_names"}},
                                    {"B", {"state_names", "input_names"}},
                                    {"C", {"output_names", "state_names"}},
                                    {"D", {"output_names", "input_names"}}}))
      fmt::print(stderr, "wrote {}\n", p);
  return 0;
}

}  // namespace linearize_command

Subcommand add_linearize(CLI::App& app) {
  auto o = std::make_shared<linearize_command::Options>();
  CLI::App* c = app.add_subcommand(
      "linearize", "continuous-time A, B, C, D about a state, from exact derivatives of the generated code");
  add_model_option(c, o->model);
  c->add_option("--state", o->state, "STATE.json of the operating point (default: the model's initial state)")
      ->check(CLI::ExistingFile);
  c->add_option("--inputs", o->inputs,
                "inputs (columns of B, D): named inputs or their entries, or tau.<speed> (default: every named "
                "input, else every tau)")
      ->delimiter(',');
  c->add_option("--outputs", o->outputs,
                "outputs (rows of C, D): sensors or their entries (default: every named output, else the state)")
      ->delimiter(',');
  c->add_option("--format", o->format, "json (default), npz (numpy), mat (MATLAB) or csv (one file per matrix)")
      ->check(CLI::IsMember({"json", "npz", "mat", "csv"}));
  o->output_option = c->add_option("-o,--output", o->output, "output file (csv: the prefix of OUT_A.csv ...); JSON goes to stdout without it");
  c->add_flag("--finite-differences", o->finite_differences,
              "central differences instead of the exact derivatives (a cross-check)");
  c->add_flag("--drop-ignorable", o->drop_ignorable,
              "leave out the ignorable coordinates (nothing else depends on them: a balanced wheel's angle, a free "
              "body's position without gravity); exact for the other states");
  c->add_option("--frame", o->frame,
                "inertial (default): the state as the model has it; lvlh: the free root body's position, attitude "
                "and rates relative to the orbit frame (a central field: an LVLH-pointing spacecraft on a circular "
                "orbit is then an equilibrium, its librations eigenvalues)")
      ->check(CLI::IsMember({"inertial", "lvlh"}));
  c->add_flag("--quiet", o->quiet, "no eigenvalue table on stderr");
  add_engine_option(c, o->engine, o->native);
  return {c, [o] { return linearize_command::run(*o); }};
}

}  // namespace kanegen::cli
