// kanegen check MODEL: validate; list bodies, joints, dofs, modes.
#include <fmt/format.h>

#include "apps/kanegen/cli_common.hpp"
#include "model/events.hpp"
#include "model/mode_description.hpp"
#include "model/orbit_plausibility.hpp"
#include "sim/mass_properties.hpp"

namespace kanegen::cli {

namespace check_command {

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

constexpr double kDeg = 57.29577951308232;

void print_orbit(const Model& model) {
  const OrbitElements& el = model.initial_orbit->elements;
  const OrbitDescription d = describe_orbit(model);
  fmt::print("  orbit of the centre of mass: a {:.10g} m, e {:.6g}, i {:.6g} deg, raan {:.6g} deg, argp {:.6g} deg, "
             "nu {:.6g} deg{}; period {:.6g} s ({:.4g} min)\n",
             el.a, el.e, el.i * kDeg, el.raan * kDeg, el.argp * kDeg, el.nu * kDeg,
             model.initial_orbit->lvlh ? ", attitude: lvlh" : "", d.period, d.period / 60.0);
  if (d.radius > 0.0)
    fmt::print("    perigee altitude {:.6g} km, apogee altitude {:.6g} km (over the radius {:.10g} m: {})\n",
               (d.r_perigee - d.radius) / 1e3, (d.r_apogee - d.radius) / 1e3, d.radius, d.radius_from);
  else
    fmt::print("    perigee radius {:.6g} km, apogee radius {:.6g} km (no central radius given)\n", d.r_perigee / 1e3,
               d.r_apogee / 1e3);
  for (const Diagnostic& w : d.warnings) fmt::print(stderr, "warning: {}\n", w.str());
}

std::string body_list(const Model& model, const std::vector<int>& bodies) {
  std::string s;
  for (const int b : bodies) s += (s.empty() ? "" : ", ") + model.bodies[b].name;
  return s;
}

void print_locks_events(const Model& model) {
  std::vector<int> locked;
  for (std::size_t i = 0; i < model.bodies.size(); ++i)
    if (model.bodies[i].joint.locked) locked.push_back(static_cast<int>(i));
  if (!locked.empty()) fmt::print("  locked at the start: {}\n", body_list(model, locked));
  for (const Event& e : model.events) {
    const std::string when = e.trigger == Event::Trigger::time
                                 ? fmt::format("at t = {:.10g} s", e.at)
                                 : fmt::format("when {} reaches {:.10g}", model.q_names[e.coordinate], e.reaches);
    std::string what;
    if (!e.lock.empty()) what += "locks " + body_list(model, e.lock);
    if (!e.release.empty()) what += (what.empty() ? "releases " : "; releases ") + body_list(model, e.release);
    fmt::print("  event {}: {}, {}\n", e.name, when, what);
  }
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
  print_locks_events(model);
  if (model.central && model.initial_orbit) print_orbit(model);
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

}  // namespace check_command

Subcommand add_check(CLI::App& app) {
  auto model = std::make_shared<std::string>();
  CLI::App* c = app.add_subcommand("check", "validate a model; print bodies, joints, dofs, modes");
  add_model_option(c, *model);
  return {c, [model] { return check_command::run(*model); }};
}

}  // namespace kanegen::cli
