// kanegen modes MODEL --body B -o OUT.modal.yaml [--second-order]: a flexible
// body's modes (e.g. of a built-in beam) as a modal data file, with its node
// inertias and second-order (foreshortening) data; --second-order computes
// that data from the shapes when the body's modal file lacks it and its nodes
// form a chain from the body origin (model/second_order.hpp).
#include <fmt/format.h>

#include "apps/kanegen/cli_common.hpp"
#include "model/diagnostics.hpp"
#include "model/modal_data.hpp"
#include "model/second_order.hpp"
#include "engine/load_model.hpp"
#include "model/model_files.hpp"
#include "model/output_file.hpp"

namespace kanegen::cli {

namespace modes_command {

struct Options {
  std::string model, body, output;
  bool second_order = false;
};

int run(const Options& o) {
  const Model model = load_model(o.model);
  check_output_options({{"-o", o.output}}, model_files(model));
  const int i = model.body_index(o.body);
  if (i < 0 || !model.bodies[i].flex)
    throw InputError(Diagnostic{o.model, 0, "--body",
                                fmt::format("'{}' is not a flexible body of model {}", o.body, model.name)});
  FlexibleData f = *model.bodies[i].flex;
  bool any = false;
  for (int k = 0; k < static_cast<int>(f.nodes.size()); ++k) any = any || f.has_second_order(k);
  if (o.second_order && !any) {
    try {
      compute_chain_second_order(f);
    } catch (const std::invalid_argument& e) {
      throw InputError(Diagnostic{f.source, 0, "second_order", e.what()});
    }
    fmt::print("{}: second_order computed from the shapes along the chain of nodes\n", o.output);
  }
  write_modal_file(f, o.output);
  fmt::print("{}: {} nodes, {} modes of body {} ({})\n", o.output, f.nodes.size(), f.modes(), o.body, f.source);
  for (int k = 0; k < f.modes(); ++k) fmt::print("  mode {}: {:.6g} Hz\n", k + 1, f.frequency_hz(k));
  return 0;
}

}  // namespace modes_command

Subcommand add_modes(CLI::App& app) {
  auto o = std::make_shared<modes_command::Options>();
  CLI::App* c =
      app.add_subcommand("modes", "write a flexible body's modes (e.g. of a built-in beam) as a modal file");
  add_model_option(c, o->model);
  c->add_option("--body", o->body, "flexible body")->required();
  c->add_option("-o,--output", o->output, "output *.modal.yaml")->required();
  c->add_flag("--second-order", o->second_order,
              "compute second_order (foreshortening) data from the shapes if the body has none (nodes along a chain "
              "from the origin)");
  return {c, [o] { return modes_command::run(*o); }};
}

}  // namespace kanegen::cli
