#include "model/model_hash.hpp"

#include <algorithm>

#include <fmt/format.h>

#include <iterator>

namespace kanegen {

namespace {

// Appends to a string; every number with {:.17g} (round-trips a double).
class Writer {
 public:
  std::string out;

  void num(double x) {
    if (x == 0.0) x = 0.0;  // -0 and +0 describe the same model
    fmt::format_to(std::back_inserter(out), " {:.17g}", x);
  }
  void integer(long long i) { fmt::format_to(std::back_inserter(out), " {}", i); }
  // Strings are length-prefixed so that no name can imitate a field separator.
  void str(const std::string& s) { fmt::format_to(std::back_inserter(out), " {}:{}", s.size(), s); }
  void key(const char* k) {
    if (!out.empty()) out += '\n';
    out += k;
  }
  template <class Derived>
  void mat(const Eigen::DenseBase<Derived>& m) {
    integer(m.rows());
    integer(m.cols());
    for (Eigen::Index i = 0; i < m.rows(); ++i)
      for (Eigen::Index j = 0; j < m.cols(); ++j) num(m(i, j));
  }
};

}  // namespace

std::string model_fingerprint(const Model& model) {
  Writer w;
  w.key("kanegen-model-fingerprint 1");
  w.key("name");
  w.str(model.name);
  w.key("gravity");
  w.mat(model.g_N);
  if (model.central) {  // only then: the fingerprints of uniform-gravity models stay as they were
    w.key("central gravity");
    w.mat(Vec3(model.central->mu, model.central->J2, model.central->radius));
  }
  w.key("nq");
  w.integer(model.nq);
  w.key("nu");
  w.integer(model.nu);
  w.key("q_names");
  w.integer(static_cast<long long>(model.q_names.size()));
  for (const auto& n : model.q_names) w.str(n);
  w.key("u_names");
  w.integer(static_cast<long long>(model.u_names.size()));
  for (const auto& n : model.u_names) w.str(n);
  w.key("outputs");
  w.integer(model.outputs.energy);
  w.integer(model.outputs.momentum);
  w.integer(model.outputs.reactions);
  if (!model.inputs.empty() || !model.sensors.empty()) {  // older models keep their hash
    w.key("inputs");
    w.integer(static_cast<long long>(model.inputs.size()));
    for (const Input& in : model.inputs) {
      w.str(in.name);
      w.str(to_string(in.type));
      w.integer(in.body);
      w.mat(in.point_B);
      w.mat(in.direction_B);
      w.str(to_string(in.axes));
      w.mat(in.R_BX);
      if (in.node >= 0) w.integer(in.node);  // older models keep their hash
    }
    w.key("sensors");
    w.integer(static_cast<long long>(model.sensors.size()));
    for (const Sensor& s : model.sensors) {
      w.str(s.name);
      w.str(to_string(s.type));
      w.integer(s.body);
      w.mat(s.point_B);
      w.integer(s.node);
      w.mat(s.R_BX);
    }
  }
  w.key("bodies");
  w.integer(static_cast<long long>(model.bodies.size()));
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const Body& b = model.bodies[i];
    w.key("body");
    w.integer(static_cast<long long>(i));
    w.str(b.name);
    w.key(" parent");
    w.integer(b.parent);
    w.key(" layout");
    w.integer(b.q_joint);
    w.integer(b.u_joint);
    w.integer(b.q_eta);
    w.integer(b.u_eta);
    const Joint& j = b.joint;
    w.key(" joint");
    w.str(to_string(j.type));
    w.key(" axis");
    w.mat(j.axis_J);
    w.key(" position");
    w.mat(j.p_PJ);
    w.key(" rotation");
    w.mat(j.R_PJ);
    w.key(" node");
    w.integer(j.node);
    if (!j.axes_J.empty()) {  // universal, gimbal (absent from the older joints' hash)
      w.key(" axes");
      for (const Vec3& a : j.axes_J) w.mat(a);
    }
    w.key(" spring");
    const int n_springs = std::max(1, joint_traits(j.type).springs);  // one entry for the one-coordinate joints, as before
    for (int k = 0; k < n_springs; ++k) {
      w.num(j.stiffness[k]);
      w.num(j.damping[k]);
      w.num(j.rest[k]);
    }
    if (j.motion) {
      const PrescribedMotion& mo = *j.motion;
      w.key(" motion");
      w.str(to_string(mo.kind));
      for (double c : mo.coefficients) w.num(c);
      for (double x : {mo.offset, mo.amplitude, mo.frequency_hz, mo.phase, mo.rate, mo.duration, mo.start}) w.num(x);
    }
    w.key(" mass");
    w.num(b.rigid.mass);
    w.key(" com");
    w.mat(b.rigid.com_B);
    w.key(" inertia");
    w.mat(b.rigid.I_c_B);
    w.key(" flexible");
    w.integer(b.flex.has_value());
    if (b.flex) {
      const FlexibleData& f = *b.flex;
      w.key(" nodes");
      w.integer(static_cast<long long>(f.nodes.size()));
      for (const ModalNode& n : f.nodes) {
        w.key("  node");
        w.integer(n.id);
        w.mat(n.rho_B);
        w.num(n.mass);
        w.mat(n.J_B);
      }
      w.key(" Phi");
      w.mat(f.Phi);
      w.key(" Psi");
      w.mat(f.Psi);
      w.key(" frequency_hz");
      w.mat(f.frequency_hz);
      w.key(" damping_ratio");
      w.mat(f.damping_ratio);
      w.key(" K");
      w.mat(f.K);
      w.key(" D");
      w.mat(f.D);
      for (std::size_t k = 0; k < f.Gamma.size(); ++k)
        for (int a = 0; a < 3; ++a)
          if (f.Gamma[k][a].size()) {
            w.key(" Gamma");
            w.integer(static_cast<long long>(k));
            w.integer(a);
            w.mat(f.Gamma[k][a]);
          }
    }
  }
  w.out += '\n';
  return w.out;
}

std::uint64_t fnv1a64(std::string_view bytes) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

std::string fnv1a64_hex(std::string_view bytes) { return fmt::format("{:016x}", fnv1a64(bytes)); }

std::string model_hash(const Model& model) {
  if (model.parameters.empty()) return fnv1a64_hex(model_fingerprint(model));
  // Runtime parameters: their names count, their values do not (the
  // generated code reads them at run time): hash the model with each one
  // at a fixed placeholder value.
  Model m = model;
  for (const RuntimeParameter& p : m.parameters) {
    if (p.kind == ParameterKind::gravity) {
      m.g_N(p.index) = 0;
      continue;
    }
    if (p.kind == ParameterKind::central) {
      (p.index == 0 ? m.central->mu : m.central->J2) = 0;
      continue;
    }
    Body& b = m.bodies[p.body];
    switch (p.kind) {
      case ParameterKind::mass: b.rigid.mass = 0; break;
      case ParameterKind::com: b.rigid.com_B(p.index) = 0; break;
      case ParameterKind::inertia: b.rigid.I_c_B.setZero(); break;
      case ParameterKind::stiffness: b.joint.stiffness[p.index] = 0; break;
      case ParameterKind::damping: b.joint.damping[p.index] = 0; break;
      case ParameterKind::rest: b.joint.rest[p.index] = 0; break;
      case ParameterKind::frequency:
      case ParameterKind::damping_ratio:
        b.flex->frequency_hz(p.index) = b.flex->damping_ratio(p.index) = b.flex->K(p.index) = b.flex->D(p.index) = 0;
        break;
      case ParameterKind::position: b.joint.p_PJ(p.index) = 0; break;
      case ParameterKind::misalignment: break;  // nominal 0: the rotation is the model's
      case ParameterKind::gravity:
      case ParameterKind::central: break;
    }
  }
  std::string f = model_fingerprint(m) + "runtime parameters";
  for (const RuntimeParameter& p : m.parameters) f += " " + p.name;
  return fnv1a64_hex(f);
}

}  // namespace kanegen
