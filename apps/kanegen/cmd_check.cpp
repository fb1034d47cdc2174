// kanegen check MODEL: validate; list bodies, joints, dofs, modes.
#include <fmt/format.h>

#include "apps/kanegen/cli_common.hpp"

namespace kanegen::cli {

namespace {

int run(const std::string& path) {
  const Model model = load_checked(path);
  fmt::print("model {}: {} bodies, nq = {}, nu = {}\n", model.name, model.bodies.size(), model.nq, model.nu);
  if (!model.description.empty()) fmt::print("  {}\n", model.description);
  for (const Body& b : model.bodies) {
    std::string parent = b.parent < 0 ? "ground" : model.bodies[b.parent].name;
    if (b.joint.node >= 0) parent += fmt::format(" @node {}", model.bodies[b.parent].flex->nodes[b.joint.node].id);
    fmt::print("  {:<16} {:<11} joint to {:<16} mass {:.6g} kg", b.name, to_string(b.joint.type), parent,
               b.total_mass);
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

}  // namespace

Subcommand add_check(CLI::App& app) {
  auto model = std::make_shared<std::string>();
  CLI::App* c = app.add_subcommand("check", "validate a model; print bodies, joints, dofs, modes");
  add_model_option(c, *model);
  return {c, [model] { return run(*model); }};
}

}  // namespace kanegen::cli
