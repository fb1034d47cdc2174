#include "model/state_io.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "model/input_text.hpp"
#include "model/json_lines.hpp"

namespace kanegen {

State initial_state(const Model& model) {
  State s;
  s.t = 0.0;
  s.q = model.q0.size() == model.nq ? model.q0 : VecX::Zero(model.nq);
  s.u = model.u0.size() == model.nu ? model.u0 : VecX::Zero(model.nu);
  s.tau = VecX::Zero(model.nu);
  s.w = VecX::Zero(model.nw);
  if (model.q0.size() != model.nq)
    for (const auto& slot : model.quaternions) s.q(slot.q) = 1.0;
  s.locked = initial_locks(model);
  return s;
}

namespace {

int find_name(const std::vector<std::string>& names, const std::string& n) {
  auto it = std::find(names.begin(), names.end(), n);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

std::string hint(const std::string& name, const std::vector<std::string>& names) {
  // Close names (same body, or a one-letter slip) help more than the whole list.
  std::vector<std::string> close;
  const auto dot = name.find('.');
  for (const auto& n : names)
    if (dot != std::string::npos && n.compare(0, dot + 1, name, 0, dot + 1) == 0) close.push_back(n);
  const auto& list = close.empty() ? names : close;
  std::string s;
  for (std::size_t i = 0; i < list.size() && i < 20; ++i) s += (i ? ", " : "") + list[i];
  if (list.size() > 20) s += ", ...";
  return list.empty() ? "(none)" : s;
}

void sort_by_line(std::vector<Diagnostic>& ds) {
  std::stable_sort(ds.begin(), ds.end(), [](const Diagnostic& a, const Diagnostic& b) { return a.line < b.line; });
}

}  // namespace

State load_state(const Model& model, const std::string& path) {
  std::vector<Diagnostic> diags;
  const std::optional<std::string> text = read_input_text(path, kMaxStateFileBytes, diags);
  if (!text) throw InputError(diags);
  const JsonValue root = parse_json_with_lines(*text, path);
  auto err = [&](int line, const std::string& field, const std::string& msg) {
    diags.push_back(Diagnostic{path, line, field, msg});
  };
  if (root.kind != JsonValue::Kind::object) {
    err(root.line, "(document)", fmt::format("got {}; expected a JSON object {{\"t\", \"q\", \"u\", \"tau\"}}",
                                   root.kind_name()));
    throw InputError(diags);
  }
  /// The members of an object, each key once: a repeated key is refused with both lines.
  auto unique_members = [&](const JsonValue& obj, const std::string& prefix) {
    std::vector<const JsonValue::Member*> out;
    for (const auto& m : obj.members) {
      const std::string field = prefix.empty() ? (m.key.empty() ? std::string("''") : m.key) : prefix + "." + m.key;
      auto same = std::find_if(out.begin(), out.end(), [&](const JsonValue::Member* o) { return o->key == m.key; });
      if (same != out.end()) {
        err(m.key_line, field,
            fmt::format("given twice (also on line {}); expected each name once", (*same)->key_line));
        continue;
      }
      out.push_back(&m);
    }
    return out;
  };
  auto number = [&](const JsonValue::Member& m, const std::string& field, double& out) {
    if (m.value.kind != JsonValue::Kind::number) {
      err(m.value.line, field, fmt::format("got {}; expected a number", m.value.kind_name()));
      return false;
    }
    if (!std::isfinite(m.value.number)) {
      err(m.value.line, field,
          fmt::format("{} is out of the range of a double; expected a finite number", m.value.text));
      return false;
    }
    out = m.value.number;
    return true;
  };

  State s = initial_state(model);
  const auto top = unique_members(root, "");
  const JsonValue::Member* sections[4] = {nullptr, nullptr, nullptr, nullptr};
  const JsonValue::Member* locked = nullptr;
  for (const auto* m : top) {
    if (m->key == "t") {
      number(*m, "t", s.t);
    } else if (m->key == "locked") {
      locked = m;
    } else if (m->key == "q" || m->key == "u" || m->key == "tau" || m->key == "inputs") {
      sections[m->key == "q" ? 0 : m->key == "u" ? 1 : m->key == "tau" ? 2 : 3] = m;
      if (m->key == "q") s.q_line = m->key_line;
    } else {
      err(m->key_line, m->key.empty() ? "''" : m->key,
          fmt::format("unknown key '{}'; expected only t, q, u, tau, inputs, locked", m->key));
    }
  }

  std::map<std::string, int> given_q;  // name -> line
  const char* keys[4] = {"q", "u", "tau", "inputs"};
  std::map<int, int> u_line;  // speed index -> line of its "u" entry
  const std::vector<std::string>* names[4] = {&model.q_names, &model.u_names, &model.u_names, &model.input_names};
  VecX* targets[4] = {&s.q, &s.u, &s.tau, &s.w};
  for (int k = 0; k < 4; ++k) {
    const JsonValue::Member* sec = sections[k];
    if (!sec) continue;
    if (sec->value.kind != JsonValue::Kind::object) {
      err(sec->value.line, keys[k],
          fmt::format("got {}; expected an object {{name: number}}", sec->value.kind_name()));
      continue;
    }
    std::map<int, std::string> speed_given;  // u, tau: a speed named once, by its name or its older one
    for (const auto* m : unique_members(sec->value, keys[k])) {
      const std::string field = std::string(keys[k]) + "." + m->key;
      const int idx = k == 1 || k == 2 ? model.speed_index(m->key) : find_name(*names[k], m->key);
      if (idx >= 0 && (k == 1 || k == 2)) {
        if (auto it = speed_given.find(idx); it != speed_given.end()) {
          err(m->key_line, field,
              fmt::format("'{}' and '{}' name the same speed; expected it once", it->second, m->key));
          continue;
        }
        speed_given[idx] = m->key;
      }
      if (idx < 0) {
        const bool prescribed =
            k == 0 && std::find(model.prescribed_names.begin(), model.prescribed_names.end(), m->key) !=
                          model.prescribed_names.end();
        err(m->key_line, field,
            prescribed ? fmt::format("'{}' is prescribed by its joint's motion: (a known function of time); "
                                     "expected no value for it",
                                     m->key)
                   : names[k]->empty() ? fmt::format("unknown name '{}'; the model declares no {}", m->key,
                                                     k == 3 ? "inputs (docs/gnc.md)" : "such names")
                       : fmt::format("unknown name '{}'; expected one of: {}", m->key, hint(m->key, *names[k])));
        continue;
      }
      double x = 0;
      if (!number(*m, field, x)) continue;
      (*targets[k])(idx) = x;
      if (k == 0) given_q[m->key] = m->key_line;
      if (k == 1) u_line[idx] = m->key_line;
    }
  }

  // "locked": the bodies whose joints are locked at this state; their speeds 0 or absent
  if (locked) {
    std::fill(s.locked.begin(), s.locked.end(), 0);
    if (locked->value.kind != JsonValue::Kind::array) {
      err(locked->value.line, "locked", fmt::format("got {}; expected a list of body names", locked->value.kind_name()));
    } else {
      std::vector<std::string> bodies;
      for (const Body& b : model.bodies) bodies.push_back(b.name);
      for (std::size_t k = 0; k < locked->value.items.size(); ++k) {
        const JsonValue& v = locked->value.items[k];
        const std::string field = fmt::format("locked[{}]", k);
        if (v.kind != JsonValue::Kind::string) {
          err(v.line, field, fmt::format("got {}; expected a body name", v.kind_name()));
          continue;
        }
        const int b = model.body_index(v.text);
        if (b < 0) {
          err(v.line, field, fmt::format("no body named '{}'; expected one of: {}", v.text, hint(v.text, bodies)));
          continue;
        }
        if (!joint_can_lock(model.bodies[b].joint)) {
          err(v.line, field,
              fmt::format("the joint of '{}' {}; expected a body whose joint has degrees of freedom", v.text,
                          model.bodies[b].joint.prescribed() ? "is prescribed (motion:)" : "has no degree of freedom"));
          continue;
        }
        s.locked[b] = 1;
      }
    }
  }
  for (int k : locked_speeds(model, s.locked))
    if (s.u(k) != 0.0)
      err(u_line.count(k) ? u_line[k] : locked ? locked->key_line : 0, "u." + model.u_names[k],
          fmt::format("{} for a speed of '{}', whose joint is locked; expected 0 or none (a locked joint does not "
                      "move)",
                      s.u(k), model.bodies[joint_body_of_speed(model, k)].name));

  // Quaternions: all four components or none; any non-zero norm is
  // normalized, robustly (scaled by the largest component first, so that
  // tiny and huge components neither underflow nor overflow).
  for (const auto& slot : model.quaternions) {
    const Body& b = model.bodies[slot.body];
    std::vector<std::string> comp, have, lack;
    for (int c = 0; c < 4; ++c) comp.push_back(model.q_names[slot.q + c]);
    for (const auto& c : comp) (given_q.count(c) ? have : lack).push_back(c);
    if (have.empty()) continue;
    const int line = given_q[have[0]];
    if (!lack.empty()) {
      std::string l;
      for (std::size_t i = 0; i < lack.size(); ++i) l += (i ? ", " : "") + lack[i];
      err(line, "q." + have[0],
          fmt::format("quaternion of '{}' given in part ({} missing); expected all of {}.qw, .qx, .qy, .qz or none",
                      b.name, l, b.name));
      continue;
    }
    auto q = s.q.segment<4>(slot.q);
    const double scale = q.cwiseAbs().maxCoeff();
    if (!(scale > 0.0)) {
      err(line, "q." + b.name + ".qw",
          fmt::format("quaternion of '{}' is zero; expected a non-zero quaternion", b.name));
      continue;
    }
    q /= scale;
    q /= q.norm();
  }
  if (!diags.empty()) {
    sort_by_line(diags);
    throw InputError(diags);
  }
  return s;
}

}  // namespace kanegen
