// kanegen modes MODEL --body B -o OUT.modal.yaml: a flexible body's modes
// (e.g. of a built-in beam) as a modal data file.
#include <fmt/format.h>

#include "apps/kanegen/cli_common.hpp"
#include "model/diagnostics.hpp"
#include "model/modal_data.hpp"
#include "model/model_loader.hpp"
#include "model/output_file.hpp"

namespace kanegen::cli {

namespace {

struct Options {
  std::string model, body, output;
};

int run(const Options& o) {
  check_output_path(o.output);
  const Model model = load_model(o.model);
  const int i = model.body_index(o.body);
  if (i < 0 || !model.bodies[i].flex)
    throw InputError(Diagnostic{o.model, 0, "--body",
                                fmt::format("'{}' is not a flexible body of model {}", o.body, model.name)});
  const FlexibleData& f = *model.bodies[i].flex;
  write_modal_file(f, o.output);
  fmt::print("{}: {} nodes, {} modes of body {} ({})\n", o.output, f.nodes.size(), f.modes(), o.body, f.source);
  for (int k = 0; k < f.modes(); ++k) fmt::print("  mode {}: {:.6g} Hz\n", k + 1, f.frequency_hz(k));
  return 0;
}

}  // namespace

Subcommand add_modes(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* c =
      app.add_subcommand("modes", "write a flexible body's modes (e.g. of a built-in beam) as a modal file");
  add_model_option(c, o->model);
  c->add_option("--body", o->body, "flexible body")->required();
  c->add_option("-o,--output", o->output, "output *.modal.yaml")->required();
  return {c, [o] { return run(*o); }};
}

}  // namespace kanegen::cli
