// kanegen check MODEL: validate; list bodies, joints, dofs, modes.
#include <fmt/format.h>

#include "apps/kanegen/cli_common.hpp"
#include "model/mode_description.hpp"
#include "sim/mass_properties.hpp"

namespace kanegen::cli {

namespace {

std::string vec(const Vec3& v, const char* fmt_one = "{:.6g}") {
  return fmt::format("[{}, {}, {}]", fmt::format(fmt::runtime(fmt_one), v.x()), fmt::format(fmt::runtime(fmt_one), v.y()),
                     fmt::format(fmt::runtime(fmt_one), v.z()));
}

std::string percent(const Vec3& part, const Vec3& whole) {
  auto one = [](double p, double w) { return w > 0.0 ? fmt::format("{:.1f} %", 100.0 * p / w) : std::string("-"); };
  return fmt::format("[{}, {}, {}]", one(part.x(), whole.x()), one(part.y(), whole.y()), one(part.z(), whole.z()));
}

void print_modes(const Body& b) {
  const FlexibleBodyModes d = describe_modes(b);
  Vec3 mass_sum = Vec3::Zero(), inertia_sum = Vec3::Zero();
  for (int k = 0; k < b.n_modes(); ++k) {
    const ModeDescription& m = d.modes[k];
    fmt::print("\n    mode {}: {:.6g} Hz, damping ratio {:.3g}, {}; effective mass {} kg, inertia about O {} kg m^2",
               k + 1, b.flex->frequency_hz(k), b.flex->damping_ratio(k), m.shape, vec(m.effective_mass, "{:.4g}"),
               vec(m.effective_inertia, "{:.4g}"));
    mass_sum += m.effective_mass;
    inertia_sum += m.effective_inertia;
  }
  fmt::print("\n    the {} modes carry {} of the moving nodes' {:.6g} kg along x, y, z and {} of their inertia about O",
             b.n_modes(), percent(mass_sum, Vec3::Constant(d.node_mass)), d.node_mass,
             percent(inertia_sum, d.node_inertia_O));
}

int run(const std::string& path) {
  const Model model = load_checked(path);
  fmt::print("model {}: {} bodies, nq = {}, nu = {}\n", model.name, model.bodies.size(), model.nq, model.nu);
  if (!model.description.empty()) fmt::print("  {}\n", model.description);
  if (model.central)
    fmt::print("  gravity: central body at N's origin, mu {:.10g} m^3/s^2{}\n", model.central->mu,
               model.central->J2 != 0.0 ? fmt::format(", J2 {:.10g} at radius {:.10g} m", model.central->J2,
                                                      model.central->radius)
                                        : std::string());
  else if (!model.g_N.isZero(0.0))
    fmt::print("  gravity: uniform [{:.6g}, {:.6g}, {:.6g}] m/s^2 (N)\n", model.g_N.x(), model.g_N.y(), model.g_N.z());
  for (const Body& b : model.bodies) {
    std::string parent = b.parent < 0 ? "ground" : model.bodies[b.parent].name;
    if (b.joint.node >= 0) parent += fmt::format(" @node {}", model.bodies[b.parent].flex->nodes[b.joint.node].id);
    fmt::print("  {:<16} {:<11} joint to {:<16} mass {:.6g} kg", b.name, to_string(b.joint.type), parent,
               b.total_mass);
    if (b.flex) {
      fmt::print(", flexible: {} modes, {} nodes ({})", b.n_modes(), b.flex->nodes.size(), b.flex->source);
      print_modes(b);
    }
    fmt::print("\n");
  }
  std::string dofs;
  for (const auto& n : model.u_names) dofs += (dofs.empty() ? "" : ", ") + n;
  fmt::print("  speeds: {}\n", dofs);
  const SystemMassProperties p = system_mass_properties(model, initial_state(model));
  fmt::print("  whole spacecraft at the initial state: mass {:.6g} kg, centre of mass {} m (N)\n", p.mass,
             vec(p.com_N));
  fmt::print("    inertia about the centre of mass (N axes) [[{:.6g}, {:.6g}, {:.6g}], [{:.6g}, {:.6g}, {:.6g}], "
             "[{:.6g}, {:.6g}, {:.6g}]] kg m^2\n",
             p.J_com_N(0, 0), p.J_com_N(0, 1), p.J_com_N(0, 2), p.J_com_N(1, 0), p.J_com_N(1, 1), p.J_com_N(1, 2),
             p.J_com_N(2, 0), p.J_com_N(2, 1), p.J_com_N(2, 2));
  fmt::print("    principal moments {} kg m^2\n", vec(p.principal_moments));
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
