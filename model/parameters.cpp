#include "model/parameters.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>

#include "model/modal_integrals.hpp"
#include "model/rotation.hpp"

namespace kanegen {

namespace {

constexpr double kTwoPi = 6.283185307179586476925;
const char* kAxis[3] = {"x", "y", "z"};
const char* kInertia[6] = {"xx", "yy", "zz", "xy", "xz", "yz"};
const int kInertiaRC[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};

}  // namespace

std::vector<RuntimeParameter> expand_parameter(const Model& model, const std::string& name) {
  std::vector<RuntimeParameter> out;
  auto add = [&](std::string n, const char* unit, ParameterKind k, int body, int index) {
    RuntimeParameter p{std::move(n), unit, k, body, index, 0.0};
    p.nominal = parameter_value(model, p);
    out.push_back(p);
  };
  if (name == "gravity.mu" || name == "gravity.J2") {
    if (!model.central)
      throw std::invalid_argument(fmt::format("'{}': the model has no central gravity (gravity: central:)", name));
    add(name, name == "gravity.mu" ? "m^3/s^2" : "", ParameterKind::central, -1, name == "gravity.mu" ? 0 : 1);
    return out;
  }
  if (name == "gravity" || name.rfind("gravity.", 0) == 0) {
    for (int a = 0; a < 3; ++a)
      if (name == "gravity" || name == std::string("gravity.") + kAxis[a])
        add(std::string("gravity.") + kAxis[a], "m/s^2", ParameterKind::gravity, -1, a);
    if (out.empty())
      throw std::invalid_argument(fmt::format("'{}': expected gravity, gravity.x, .y, .z, gravity.mu or gravity.J2", name));
    return out;
  }
  const auto dot = name.find('.');
  if (dot == std::string::npos)
    throw std::invalid_argument(fmt::format("'{}': expected <body>.<quantity> or gravity", name));
  const std::string body = name.substr(0, dot), what = name.substr(dot + 1);
  const int b = model.body_index(body);
  if (b < 0) throw std::invalid_argument(fmt::format("'{}': no body named '{}'", name, body));
  const Body& B = model.bodies[b];
  const Joint& j = B.joint;
  const JointTraits& jt = joint_traits(j.type);
  const int n_springs = j.prescribed() ? 0 : jt.springs;
  if (what == "mass") {
    add(name, "kg", ParameterKind::mass, b, 0);
  } else if (what == "com" || what.rfind("com.", 0) == 0) {
    for (int a = 0; a < 3; ++a)
      if (what == "com" || what == std::string("com.") + kAxis[a])
        add(body + ".com." + kAxis[a], "m", ParameterKind::com, b, a);
  } else if (what == "inertia" || what.rfind("inertia.", 0) == 0) {
    for (int k = 0; k < 6; ++k)
      if (what == "inertia" || what == std::string("inertia.") + kInertia[k])
        add(body + ".inertia." + kInertia[k], "kg m^2", ParameterKind::inertia, b, k);
  } else if (what == "position" || what.rfind("position.", 0) == 0 || what == "misalignment" ||
             what.rfind("misalignment.", 0) == 0) {
    const bool pos = what.rfind("position", 0) == 0;
    if (j.node >= 0)
      throw std::invalid_argument(fmt::format("'{}': body '{}' is attached at a node of its parent, which places and "
                                              "turns its joint; expected a joint on a body frame",
                                              name, body));
    const std::string stem = pos ? "position" : "misalignment";
    for (int a = 0; a < 3; ++a)
      if (what == stem || what == stem + "." + kAxis[a])
        add(body + "." + stem + "." + kAxis[a], pos ? "m" : "rad", pos ? ParameterKind::position : ParameterKind::misalignment,
            b, a);
  } else if (const std::string stem0 = what.substr(0, what.find('.'));
             stem0 == "stiffness" || stem0 == "damping" || stem0 == "rest") {
    // <body>.stiffness (every coordinate; the name itself on a one-coordinate
    // joint) or <body>.stiffness.<coordinate>; a ball joint: <body>.damping
    const std::string& stem = stem0;
    const std::string coord = what.size() > stem.size() ? what.substr(stem.size() + 1) : "";
    const ParameterKind kind = stem == "stiffness" ? ParameterKind::stiffness : stem == "damping" ? ParameterKind::damping
                                                                                                   : ParameterKind::rest;
    if (jt.damping_only && !j.prescribed() && stem == "damping" && coord.empty()) {
      add(name, "N m s/rad", kind, b, 0);
    } else if (n_springs == 0) {
      throw std::invalid_argument(fmt::format("'{}': body '{}' has a {} joint{}; a joint spring needs a joint with "
                                              "spring coordinates (revolute, prismatic, universal, gimbal, "
                                              "cylindrical, planar; a ball joint takes damping only)",
                                              name, body, to_string(j.type), j.prescribed() ? " (prescribed)" : ""));
    } else {
      for (int k = 0; k < n_springs; ++k) {
        if (!coord.empty() && coord != jt.coordinates[k]) continue;
        const bool rad = jt.units[k] == "rad";
        const char* unit = stem == "stiffness" ? (rad ? "N m/rad" : "N/m") : stem == "damping" ? (rad ? "N m s/rad" : "N s/m")
                                                                                                : (rad ? "rad" : "m");
        add(n_springs == 1 ? body + "." + stem : body + "." + stem + "." + jt.coordinates[k], unit, kind, b, k);
      }
    }
  } else if (what.rfind("frequency", 0) == 0 || what.rfind("damping_ratio", 0) == 0) {
    const bool freq = what.rfind("frequency", 0) == 0;
    const std::string stem = freq ? "frequency" : "damping_ratio";
    if (!B.flex) throw std::invalid_argument(fmt::format("'{}': body '{}' is not flexible", name, body));
    const std::string rest = what.substr(stem.size());
    for (int i = 0; i < B.n_modes(); ++i)
      if (rest.empty() || rest == std::to_string(i + 1))
        add(body + "." + stem + std::to_string(i + 1), freq ? "Hz" : "", freq ? ParameterKind::frequency : ParameterKind::damping_ratio, b, i);
  }
  if (out.empty())
    throw std::invalid_argument(fmt::format(
        "'{}': expected <body>.mass, .com[.x], .inertia[.xy], .stiffness, .damping, .rest, .frequency[N], "
        ".damping_ratio[N] or gravity[.x]",
        name));
  return out;
}

double parameter_value(const Model& model, const RuntimeParameter& p) {
  if (p.kind == ParameterKind::gravity) return model.g_N(p.index);
  if (p.kind == ParameterKind::central) return p.index == 0 ? model.central->mu : model.central->J2;
  const Body& b = model.bodies.at(p.body);
  switch (p.kind) {
    case ParameterKind::mass: return b.rigid.mass;
    case ParameterKind::com: return b.rigid.com_B(p.index);
    case ParameterKind::inertia: return b.rigid.I_c_B(kInertiaRC[p.index][0], kInertiaRC[p.index][1]);
    case ParameterKind::stiffness: return b.joint.stiffness[p.index];
    case ParameterKind::damping: return b.joint.damping[p.index];
    case ParameterKind::rest: return b.joint.rest[p.index];
    case ParameterKind::frequency: return b.flex->frequency_hz(p.index);
    case ParameterKind::damping_ratio: return b.flex->damping_ratio(p.index);
    case ParameterKind::position: return b.joint.p_PJ(p.index);
    case ParameterKind::misalignment: return 0.0;  // relative to the model's rotation
    case ParameterKind::gravity:
    case ParameterKind::central: break;
  }
  return 0.0;
}

int find_parameter(const std::vector<RuntimeParameter>& params, ParameterKind kind, int body, int index) {
  for (std::size_t k = 0; k < params.size(); ++k)
    if (params[k].kind == kind && params[k].body == body && params[k].index == index) return static_cast<int>(k);
  return -1;
}

void apply_parameters(Model& model, const std::vector<RuntimeParameter>& params, const VecX& values) {
  if (values.size() != static_cast<Eigen::Index>(params.size()))
    throw std::invalid_argument(fmt::format("{} parameter values for {} parameters", values.size(), params.size()));
  std::vector<bool> rigid_changed(model.bodies.size(), false), modes_changed(model.bodies.size(), false);
  std::vector<Vec3> misalignment(model.bodies.size(), Vec3::Zero());
  std::vector<bool> misaligned(model.bodies.size(), false);
  for (std::size_t k = 0; k < params.size(); ++k) {
    const RuntimeParameter& p = params[k];
    const double v = values(static_cast<Eigen::Index>(k));
    auto bad = [&](const char* expected) {
      return std::invalid_argument(fmt::format("parameter {} = {}: expected {}", p.name, v, expected));
    };
    if (!std::isfinite(v)) throw bad("a finite number");
    if (p.kind == ParameterKind::gravity) {
      model.g_N(p.index) = v;
      continue;
    }
    if (p.kind == ParameterKind::central) {
      if (p.index == 0 && !(v > 0)) throw bad("a gravitational parameter mu > 0");
      (p.index == 0 ? model.central->mu : model.central->J2) = v;
      continue;
    }
    Body& b = model.bodies.at(p.body);
    switch (p.kind) {
      case ParameterKind::mass:
        if (v < 0) throw bad("a mass >= 0");
        b.rigid.mass = v;
        rigid_changed[p.body] = true;
        break;
      case ParameterKind::com:
        b.rigid.com_B(p.index) = v;
        rigid_changed[p.body] = true;
        break;
      case ParameterKind::inertia: {
        const int r = kInertiaRC[p.index][0], c = kInertiaRC[p.index][1];
        b.rigid.I_c_B(r, c) = b.rigid.I_c_B(c, r) = v;
        rigid_changed[p.body] = true;
        break;
      }
      case ParameterKind::stiffness:
        if (v < 0) throw bad("a stiffness >= 0");
        b.joint.stiffness[p.index] = v;
        break;
      case ParameterKind::damping:
        if (v < 0) throw bad("a damping >= 0");
        b.joint.damping[p.index] = v;
        break;
      case ParameterKind::rest: b.joint.rest[p.index] = v; break;
      case ParameterKind::position: b.joint.p_PJ(p.index) = v; break;
      case ParameterKind::misalignment:
        misalignment[p.body](p.index) = v;
        misaligned[p.body] = true;
        break;
      case ParameterKind::frequency:
      case ParameterKind::damping_ratio: {
        FlexibleData& f = *b.flex;
        const int i = p.index;
        if (p.kind == ParameterKind::frequency && !(v > 0)) throw bad("a frequency > 0");
        if (p.kind == ParameterKind::damping_ratio && v < 0) throw bad("a damping ratio >= 0");
        const double w0 = kTwoPi * f.frequency_hz(i), Y = f.K(i) / (w0 * w0);  // the mode's modal mass
        (p.kind == ParameterKind::frequency ? f.frequency_hz(i) : f.damping_ratio(i)) = v;
        const double w = kTwoPi * f.frequency_hz(i);
        f.K(i) = w * w * Y;
        f.D(i) = 2.0 * f.damping_ratio(i) * w * Y;
        modes_changed[p.body] = true;
        break;
      }
      case ParameterKind::gravity:
      case ParameterKind::central: break;
    }
  }
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    if (!rigid_changed[i]) continue;
    Body& b = model.bodies[i];
    const Eigen::SelfAdjointEigenSolver<Mat3> es(b.rigid.I_c_B);
    const Vec3 e = es.eigenvalues();
    const double tol = 1e-9 * std::max(1.0, e.cwiseAbs().maxCoeff());
    if (e.minCoeff() < -tol || e(0) + e(1) < e(2) - tol)
      throw std::invalid_argument(fmt::format("parameters of body '{}': inertia with principal moments {}, {}, {} is "
                                              "not physical (expected positive semi-definite, triangle inequality)",
                                              b.name, e(0), e(1), e(2)));
    b.integrals = compute_mass_integrals(b.rigid, b.flex ? &*b.flex : nullptr);  // as finalize_model
    b.total_mass = b.rigid.mass;
    if (b.flex)
      for (const auto& n : b.flex->nodes) b.total_mass += n.mass;
  }
  (void)modes_changed;
  // the model's rotation (as given: apply_parameters always starts from the loaded model), then the misalignment
  for (std::size_t i = 0; i < model.bodies.size(); ++i)
    if (misaligned[i]) {
      const Vec3& m = misalignment[i];
      model.bodies[i].joint.R_PJ = model.bodies[i].joint.R_PJ * rpy_R(m(0), m(1), m(2));
    }
}

}  // namespace kanegen

namespace kanegen {

std::vector<RuntimeParameter> implicit_parameters(const Model& model) {
  std::vector<RuntimeParameter> out;
  auto keep = [&](const std::vector<RuntimeParameter>& candidates) {
    for (const RuntimeParameter& p : candidates)
      if (parameter_value(model, p) != 0.0 && find_parameter(model.parameters, p.kind, p.body, p.index) < 0)
        out.push_back(p);
  };
  for (const Body& b : model.bodies) {
    const JointTraits& jt = joint_traits(b.joint.type);
    const bool springs = !b.joint.prescribed() && jt.springs > 0;
    const bool ball_damper = !b.joint.prescribed() && jt.damping_only;
    if (springs)
      for (const char* stem : {".stiffness", ".damping", ".rest"}) keep(expand_parameter(model, b.name + stem));
    else if (ball_damper)
      keep(expand_parameter(model, b.name + ".damping"));
    if (b.flex && b.n_modes() > 0) keep(expand_parameter(model, b.name + ".damping_ratio"));
  }
  for (RuntimeParameter& p : out) p.nominal = parameter_value(model, p);
  return out;
}

Model with_parameters(const Model& model, const std::vector<RuntimeParameter>& extra) {
  Model m = model;
  m.parameters.insert(m.parameters.end(), extra.begin(), extra.end());
  return m;
}

Model with_implicit_parameters(const Model& model) { return with_parameters(model, implicit_parameters(model)); }

int ensure_parameter(Model& model, const RuntimeParameter& p) {
  const int k = find_parameter(model.parameters, p.kind, p.body, p.index);
  if (k >= 0) return k;
  model.parameters.push_back(p);
  return static_cast<int>(model.parameters.size()) - 1;
}

}  // namespace kanegen
