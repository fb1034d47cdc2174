#include "model/state_io.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

namespace kanegen {

State initial_state(const Model& model) {
  State s;
  s.t = 0.0;
  s.q = model.q0.size() == model.nq ? model.q0 : VecX::Zero(model.nq);
  s.u = model.u0.size() == model.nu ? model.u0 : VecX::Zero(model.nu);
  s.tau = VecX::Zero(model.nu);
  if (model.q0.size() != model.nq)
    for (const Body& b : model.bodies)
      if (b.joint.type == JointType::free) s.q(b.q_joint + 3) = 1.0;
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

/// 1-based line of byte offset `pos` in text.
int line_at(const std::string& text, std::size_t pos) {
  pos = std::min(pos, text.size());
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(pos), '\n'));
}

}  // namespace

State load_state(const Model& model, const std::string& path) {
  std::vector<Diagnostic> diags;
  auto err = [&](const std::string& field, const std::string& msg) {
    diags.push_back(Diagnostic{path, 0, field, msg});
  };
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(Diagnostic{path, 0, "", "cannot open file; expected a readable STATE.json"});
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is 1-based position of the fault
    const int line = e.byte > 0 ? line_at(text, e.byte - 1) : 0;
    std::string what = e.what();
    throw InputError(Diagnostic{path, line, "", fmt::format("malformed JSON: {}", what)});
  }
  if (!j.is_object()) throw InputError(Diagnostic{path, 0, "", "expected a JSON object {\"t\", \"q\", \"u\", \"tau\"}"});

  State s = initial_state(model);
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& key = it.key();
    if (key != "t" && key != "q" && key != "u" && key != "tau")
      err(key, fmt::format("unknown key '{}'; expected only t, q, u, tau", key));
  }
  if (j.contains("t")) {
    if (!j["t"].is_number())
      err("t", fmt::format("got {}; expected a number", j["t"].dump()));
    else
      s.t = j["t"].get<double>();
  }

  std::set<std::string> given_q;
  struct Section {
    const char* key;
    const std::vector<std::string>* names;
    VecX* target;
  };
  for (const Section& sec : {Section{"q", &model.q_names, &s.q}, Section{"u", &model.u_names, &s.u},
                             Section{"tau", &model.u_names, &s.tau}}) {
    if (!j.contains(sec.key)) continue;
    const auto& obj = j[sec.key];
    if (!obj.is_object()) {
      err(sec.key, fmt::format("got {}; expected an object {{name: number}}", obj.type_name()));
      continue;
    }
    for (auto it = obj.begin(); it != obj.end(); ++it) {
      const std::string field = std::string(sec.key) + "." + it.key();
      const int k = find_name(*sec.names, it.key());
      if (k < 0) {
        err(field, fmt::format("unknown name '{}'; expected one of: {}", it.key(), hint(it.key(), *sec.names)));
        continue;
      }
      if (!it.value().is_number()) {
        err(field, fmt::format("got {}; expected a number", it.value().dump()));
        continue;
      }
      const double x = it.value().get<double>();
      if (!std::isfinite(x)) {
        err(field, "not finite; expected a finite number");
        continue;
      }
      (*sec.target)(k) = x;
      if (std::string(sec.key) == "q") given_q.insert(it.key());
    }
  }

  // Quaternions: all four components or none; any non-zero norm is normalized.
  for (const Body& b : model.bodies) {
    if (b.joint.type != JointType::free) continue;
    const char* comp[4] = {".qw", ".qx", ".qy", ".qz"};
    std::vector<std::string> have, lack;
    for (const char* c : comp) (given_q.count(b.name + c) ? have : lack).push_back(b.name + c);
    if (have.empty()) continue;
    if (!lack.empty()) {
      std::string l;
      for (std::size_t i = 0; i < lack.size(); ++i) l += (i ? ", " : "") + lack[i];
      err("q." + have[0], fmt::format("quaternion of '{}' given in part ({} missing); expected all of {}.qw, "
                                      ".qx, .qy, .qz or none",
                                      b.name, l, b.name));
      continue;
    }
    auto q = s.q.segment<4>(b.q_joint + 3);
    const double n = q.norm();
    if (!(n > 0.0)) {
      err("q." + b.name + ".qw", fmt::format("quaternion of '{}' is zero; expected a non-zero quaternion", b.name));
      continue;
    }
    q /= n;
  }
  if (!diags.empty()) throw InputError(diags);
  return s;
}

}  // namespace kanegen
