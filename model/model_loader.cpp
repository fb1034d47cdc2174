// YAML model file -> validated Model (model-format.md). Every fault found is
// recorded as a Diagnostic (file, line, field, message); all are reported
// together in one InputError.
#include "model/model_loader.hpp"
#include "model/initial_orbit.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <filesystem>
#include <map>
#include <set>

#include "model/beam.hpp"
#include "model/modal_data.hpp"
#include "model/parameters.hpp"
#include "model/rotation.hpp"
#include "model/yaml_check.hpp"

namespace kanegen {

using yamlcheck::Checker;
using yamlcheck::describe;
using yamlcheck::did_you_mean;
using yamlcheck::join;
using yamlcheck::key_line;
using yamlcheck::line_of;
using yamlcheck::num;

namespace {

constexpr std::size_t kMaxBodies = 1'000;   ///< bodies in a model (docs/limits.md)
constexpr int kMaxSpeeds = 2'000;           ///< generalized speeds in a model (M is nu x nu)
constexpr int kMaxBeamElements = 2'000;     ///< elements of a built-in beam

bool valid_model_name(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s)
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
  return true;
}

bool valid_body_name(const std::string& s) {
  if (s.empty() || !(s[0] >= 'a' && s[0] <= 'z')) return false;
  return valid_model_name(s);
}

/// What the loader knows about one body while validating.
struct BodyInfo {
  int line = 0;
  std::string name;             ///< empty if invalid
  std::string raw_name;         ///< as written (may be invalid or a duplicate)
  std::string parent_name;      ///< as written
  int parent = -2;              ///< -1 ground, >= 0 body, -2 unresolved
  bool type_known = false;
  bool has_flex_block = false;
  bool flex_known = false;      ///< modal data loaded without faults
  bool mass_known = true;       ///< rigid mass and node masses valid
  int mass_line = 0;
  int node_id = -1;             ///< `node:` id if given and valid
  int node_line = 0;
  Body body;
};

class Loader {
 public:
  explicit Loader(const std::string& path) : path_(path), ck_(path, diags_) {}

  Model load() {
    bool parsed = false;
    const YAML::Node root = yamlcheck::parse_file(path_, kMaxModelFileBytes, diags_, parsed);
    if (!parsed) throw InputError(diags_);
    try {
      read_root(root);
    } catch (const YAML::Exception& e) {
      ck_.error(e.mark.is_null() ? 1 : e.mark.line + 1, yamlcheck::mark_column(e.mark), fmt::format("cannot read YAML: {}", e.msg));
    }
    if (!diags_.empty()) {
      yamlcheck::sort_diagnostics(diags_);
      throw InputError(diags_);
    }
    return build();
  }

 private:
  std::string path_;
  std::vector<Diagnostic> diags_;
  Checker ck_;
  Model model_;
  std::vector<BodyInfo> info_;
  // initial: name -> value, line
  struct Given {
    double value;
    int line;
  };
  std::map<std::string, Given> init_q_, init_u_;
  std::vector<std::pair<std::string, int>> parameter_names_;  ///< `parameters:` entries and their lines
  int central_line_ = 0;  ///< line of `gravity: {central: ...}`
  std::optional<InitialOrbit> orbit_;  ///< `initial: orbit:`
  int orbit_line_ = 0;
  YAML::Node events_;  ///< `events:`, read when the model is built (it names bodies and coordinates)
  bool has_events_ = false;

  // ------------------------------------------------------------------ root
  void read_root(const YAML::Node& root) {
    model_.source_path = path_;
    if (!root.IsDefined() || root.IsNull()) {
      ck_.error(1, "(document)", "empty file; expected a model (a mapping with name, bodies, ...)");
      return;
    }
    if (!ck_.expect_map(root, 1, "(document)")) return;
    ck_.check_keys(root, "", {"name", "description", "gravity", "bodies", "initial", "inputs", "outputs", "parameters",
                              "events"});

    const YAML::Node name = root["name"];
    if (!name.IsDefined()) {
      ck_.error(1, "name", "missing; expected a model name matching [a-z0-9_]+");
    } else if (auto s = ck_.string(name, 1, "name")) {
      if (!valid_model_name(*s))
        ck_.error(name, 1, "name", fmt::format("'{}' is not a valid model name; expected [a-z0-9_]+", *s));
      else
        model_.name = *s;
    }
    if (root["description"].IsDefined()) {
      if (auto s = ck_.string(root["description"], 1, "description")) {
        // One line of printable text: it is copied into the generated header's comment.
        const auto bad = std::find_if(s->begin(), s->end(), [](char c) {
          const auto u = static_cast<unsigned char>(c);
          return u < 0x20 || u == 0x7F;
        });
        if (bad != s->end())
          ck_.error(root["description"], 1, "description",
                    fmt::format("control character 0x{:02x} (e.g. an escaped line break); expected one line of text",
                                static_cast<unsigned>(static_cast<unsigned char>(*bad))));
        else if (s->size() > 1000)
          ck_.error(root["description"], 1, "description",
                    fmt::format("{} characters; expected at most 1000", s->size()));
        else
          model_.description = *s;
      }
    }
    if (root["gravity"].IsDefined()) read_gravity(root["gravity"]);

    const YAML::Node bodies = root["bodies"];
    if (!bodies.IsDefined()) {
      ck_.error(1, "bodies", "missing; expected a non-empty list of bodies");
    } else if (ck_.expect_seq(bodies, 1, "bodies")) {
      if (bodies.size() == 0)
        ck_.error(bodies, 1, "bodies", "empty; expected a non-empty list of bodies");
      else if (bodies.size() > kMaxBodies)
        ck_.error(bodies, 1, "bodies",
                  fmt::format("{} bodies; expected at most {} (docs/limits.md)", bodies.size(), kMaxBodies));
      else
        read_bodies(bodies);
      check_speed_count(bodies);
    }

    check_central_roots();
    if (root["initial"].IsDefined()) read_initial(root["initial"]);
    if (root["inputs"].IsDefined()) read_inputs(root["inputs"]);
    if (root["parameters"].IsDefined() && ck_.expect_seq(root["parameters"], 1, "parameters")) {
      const YAML::Node ps = root["parameters"];
      for (std::size_t i = 0; i < ps.size(); ++i)
        if (auto s = ck_.string(ps[i], line_of(ps), fmt::format("parameters[{}]", i)))
          parameter_names_.push_back({*s, line_of(ps[i]) ? line_of(ps[i]) : line_of(ps)});
    }
    if (root["outputs"].IsDefined()) read_outputs(root["outputs"]);
    if (root["events"].IsDefined()) {
      events_.reset(root["events"]);
      has_events_ = true;
    }
  }

  // ------------------------------------------------- inputs and sensors
  static constexpr std::size_t kMaxPorts = 1000;

  /// A body named by entry `e`'s `key` (e.g. body: bus); -1 with a fault if absent or unknown.
  int port_body(const YAML::Node& e, const std::string& f, const char* key) {
    const YAML::Node n = e[key];
    const int l = line_of(e);
    if (!n.IsDefined()) {
      ck_.error(l, f + "." + key, "missing; expected the name of a body");
      return -1;
    }
    auto s = ck_.string(n, l, f + "." + key);
    if (!s) return -1;
    std::vector<std::string> names;
    for (std::size_t i = 0; i < info_.size(); ++i) {
      if (info_[i].name == *s) return static_cast<int>(i);
      if (!info_[i].name.empty()) names.push_back(info_[i].name);
    }
    ck_.error(n, l, f + "." + key, fmt::format("no body named '{}'{}", *s, did_you_mean(*s, names)));
    return -1;
  }

  /// The entry's `name:`: [a-z][a-z0-9_]*, unique in `seen`.
  std::optional<std::string> port_name(const YAML::Node& e, const std::string& f, std::set<std::string>& seen) {
    const YAML::Node n = e["name"];
    if (!n.IsDefined()) {
      ck_.error(line_of(e), f + ".name", "missing; expected a name matching [a-z][a-z0-9_]*");
      return std::nullopt;
    }
    auto s = ck_.string(n, line_of(e), f + ".name");
    if (!s) return std::nullopt;
    if (!yamlcheck::valid_identifier(*s)) {
      ck_.error(n, line_of(e), f + ".name",
                fmt::format("'{}' is not a valid name; expected [a-z][a-z0-9_]* (at most 64 characters)", *s));
      return std::nullopt;
    }
    if (!seen.insert(*s).second) {
      ck_.error(n, line_of(e), f + ".name", fmt::format("'{}' is used twice; expected unique names", *s));
      return std::nullopt;
    }
    return s;
  }

  std::optional<Axes> port_axes(const YAML::Node& e, const std::string& f) {
    const YAML::Node n = e["axes"];
    if (!n.IsDefined()) return Axes::body;
    auto s = ck_.string(n, line_of(e), f + ".axes");
    if (!s) return std::nullopt;
    if (*s == "body") return Axes::body;
    if (*s == "inertial") return Axes::inertial;
    ck_.error(n, line_of(e), f + ".axes", fmt::format("'{}'; expected body or inertial", *s));
    return std::nullopt;
  }

  void read_inputs(const YAML::Node& n) {
    if (!ck_.expect_seq(n, 1, "inputs")) return;
    if (n.size() > kMaxPorts) {
      ck_.error(n, 1, "inputs", fmt::format("{} inputs; expected at most {}", n.size(), kMaxPorts));
      return;
    }
    std::set<std::string> seen;
    const std::vector<std::string> types = {"thruster", "force", "torque", "joint_torque"};
    for (std::size_t i = 0; i < n.size(); ++i) {
      const std::string f = fmt::format("inputs[{}]", i);
      const YAML::Node e = n[i];
      if (!ck_.expect_map(e, line_of(n), f)) continue;
      const int l = line_of(e);
      auto type = e["type"].IsDefined() ? ck_.string(e["type"], l, f + ".type") : std::nullopt;
      if (!e["type"].IsDefined()) ck_.error(l, f + ".type", "missing; expected thruster, force, torque or joint_torque");
      if (!type) continue;
      Input in;
      in.line = l;
      if (*type == "thruster") {
        in.type = InputType::thruster;
        ck_.check_keys(e, f, {"name", "type", "body", "point", "direction"});
      } else if (*type == "force") {
        in.type = InputType::force;
        ck_.check_keys(e, f, {"name", "type", "body", "point", "node", "axes"});
      } else if (*type == "torque") {
        in.type = InputType::torque;
        ck_.check_keys(e, f, {"name", "type", "body", "axes"});
      } else if (*type == "joint_torque") {
        in.type = InputType::joint_torque;
        ck_.check_keys(e, f, {"name", "type", "joint", "coordinate"});
      } else {
        const std::string hint = did_you_mean(*type, types);
        ck_.error(e["type"], l, f + ".type",
                  fmt::format("unknown input type '{}'{}{}expected thruster, force, torque or joint_torque", *type,
                              hint, hint.empty() ? "; " : " "));
        continue;
      }
      auto name = port_name(e, f, seen);
      bool ok = name.has_value();
      if (name) in.name = *name;
      in.body = port_body(e, f, in.type == InputType::joint_torque ? "joint" : "body");
      ok = ok && in.body >= 0;
      if (in.type == InputType::force && e["node"].IsDefined() && in.body >= 0) {
        const BodyInfo& bi = info_[in.body];
        if (e["point"].IsDefined()) {
          ck_.error(e["node"], l, f + ".node", "given with point; expected one of point (a body point) or node");
          ok = false;
        } else if (!bi.has_flex_block) {
          ck_.error(e["node"], l, f + ".node", fmt::format("body '{}' is not flexible; a node needs a flexible body", bi.name));
          ok = false;
        } else if (auto id = ck_.integer(e["node"], l, f + ".node")) {
          if (bi.flex_known && bi.body.flex) {
            in.node = bi.body.flex->node_index(static_cast<int>(*id));
            if (in.node < 0) {
              ck_.error(e["node"], l, f + ".node", fmt::format("body '{}' has no node {} in {}", bi.name, *id, bi.body.flex->source));
              ok = false;
            }
          } else {
            ok = false;
          }
        } else {
          ok = false;
        }
      }
      if (in.type == InputType::thruster || in.type == InputType::force) {
        if (e["point"].IsDefined()) {
          if (auto p = ck_.vec3(e["point"], l, f + ".point")) in.point_B = *p; else ok = false;
        }
      }
      if (in.type == InputType::thruster) {
        if (!e["direction"].IsDefined()) {
          ck_.error(l, f + ".direction", "missing; expected the thrust direction, a unit 3-vector in body axes");
          ok = false;
        } else if (auto d = ck_.unit(e["direction"], l, f + ".direction", 3, "a unit 3-vector in body axes")) {
          in.direction_B = *d;
        } else {
          ok = false;
        }
      }
      if (in.type == InputType::force || in.type == InputType::torque) {
        if (auto a = port_axes(e, f)) in.axes = *a; else ok = false;
      }
      if (in.type == InputType::joint_torque && in.body >= 0 && info_[in.body].type_known) {
        // one scalar per speed of the joint, or the speed of one `coordinate:`;
        // a ball's (and a free joint's angular) speeds: a torque in B axes
        const Joint& j = info_[in.body].body.joint;
        const JointTraits& jt = joint_traits(j.type);
        if (jt.nu() == 0 || j.prescribed()) {
          ck_.error(e["joint"], l, f + ".joint",
                    fmt::format("body '{}' has a {} joint{}; a joint torque needs a joint with degrees of freedom",
                                info_[in.body].name, to_string(j.type), j.prescribed() ? " (prescribed)" : ""));
          ok = false;
        } else if (e["coordinate"].IsDefined()) {
          const auto c = ck_.string(e["coordinate"], l, f + ".coordinate");
          std::vector<std::string> rates;  // coordinates whose rate is a speed
          for (int k = 0; k < jt.nu(); ++k)
            if (k < jt.nq() && jt.speeds[k] == jt.coordinates[k] + "_rate") rates.push_back(jt.coordinates[k]);
          const auto it = c ? std::find(rates.begin(), rates.end(), *c) : rates.end();
          if (c && it == rates.end()) {
            ck_.error(e["coordinate"], l, f + ".coordinate",
                      fmt::format("'{}' is no coordinate of the {} joint of '{}'; expected one of: {}", *c,
                                  to_string(j.type), info_[in.body].name, rates.empty() ? "(none)" : join(rates)));
            ok = false;
          } else if (c) {
            in.speed = static_cast<int>(it - rates.begin());
          } else {
            ok = false;
          }
        } else {
          in.speeds = jt.nu();
          if (in.speeds > 1) in.speed_names = jt.speeds;
        }
      }
      if (ok) model_.inputs.push_back(in);
    }
  }

  /// One sensor entry of `outputs:` (a mapping).
  void read_sensor(const YAML::Node& e, const std::string& f, std::set<std::string>& seen) {
    const int l = line_of(e);
    const std::vector<std::string> types = {"angular_velocity", "attitude",       "position",      "velocity",
                                            "acceleration",     "specific_force", "reaction",      "deflection",
                                            "attitude_lvlh",    "angular_velocity_lvlh",
                                            "com_position",     "com_velocity",   "orbit_elements"};
    if (!e["type"].IsDefined()) {
      ck_.error(l, f + ".type", "missing; expected one of: " + join(types));
      return;
    }
    auto type = ck_.string(e["type"], l, f + ".type");
    if (!type) return;
    Sensor s;
    s.line = l;
    const auto it = std::find(types.begin(), types.end(), *type);
    if (it == types.end()) {
      const std::string hint = did_you_mean(*type, types);
      ck_.error(e["type"], l, f + ".type",
                fmt::format("unknown output type '{}'{}{}expected one of: {}", *type, hint, hint.empty() ? "; " : " ",
                            join(types)));
      return;
    }
    s.type = static_cast<SensorType>(it - types.begin());
    const bool point = s.type == SensorType::position || s.type == SensorType::velocity ||
                       s.type == SensorType::acceleration || s.type == SensorType::specific_force;
    if (point)
      ck_.check_keys(e, f, {"name", "type", "body", "point"});
    else if (s.type == SensorType::deflection)
      ck_.check_keys(e, f, {"name", "type", "body", "node"});
    else if (s.type == SensorType::reaction)
      ck_.check_keys(e, f, {"name", "type", "joint"});
    else if (system_sensor(s.type))
      ck_.check_keys(e, f, {"name", "type"});
    else
      ck_.check_keys(e, f, {"name", "type", "body"});
    auto name = port_name(e, f, seen);
    bool ok = name.has_value();
    if (name) s.name = *name;
    if (central_sensor(s.type) && !model_.central) {
      ck_.error(e["type"], l, f + ".type",
                fmt::format("'{}' is relative to the central body; expected gravity: {{central: {{mu: ...}}}} "
                            "(model-format.md, \"Gravity\")", *type));
      ok = false;
    }
    if (!system_sensor(s.type)) {
      s.body = port_body(e, f, s.type == SensorType::reaction ? "joint" : "body");
      ok = ok && s.body >= 0;
    }
    if (point && e["point"].IsDefined()) {
      if (auto p = ck_.vec3(e["point"], l, f + ".point")) s.point_B = *p; else ok = false;
    }
    if (s.type == SensorType::deflection && s.body >= 0) {
      const BodyInfo& bi = info_[s.body];
      if (!bi.has_flex_block) {
        ck_.error(e["body"], l, f + ".body", fmt::format("body '{}' is not flexible; a deflection needs a flexible body", bi.name));
        ok = false;
      } else if (!e["node"].IsDefined()) {
        ck_.error(l, f + ".node", "missing; expected a node id of the body's modal data");
        ok = false;
      } else if (auto id = ck_.integer(e["node"], l, f + ".node")) {
        if (bi.flex_known && bi.body.flex) {
          s.node = bi.body.flex->node_index(static_cast<int>(*id));
          if (s.node < 0) {
            ck_.error(e["node"], l, f + ".node",
                      fmt::format("body '{}' has no node {} in {}", bi.name, *id, bi.body.flex->source));
            ok = false;
          }
        } else {
          ok = false;
        }
      } else {
        ok = false;
      }
    }
    if (ok) model_.sensors.push_back(s);
  }


  void read_outputs(const YAML::Node& n) {
    const std::vector<std::string> allowed = {"energy", "momentum", "reactions"};
    if (!ck_.expect_seq(n, 1, "outputs")) return;
    if (n.size() > kMaxPorts) {
      ck_.error(n, 1, "outputs", fmt::format("{} outputs; expected at most {}", n.size(), kMaxPorts));
      return;
    }
    std::set<std::string> seen, sensor_names = {"energy", "momentum", "reactions"};
    for (std::size_t i = 0; i < n.size(); ++i) {
      const std::string f = fmt::format("outputs[{}]", i);
      if (n[i].IsMap()) {
        read_sensor(n[i], f, sensor_names);
        continue;
      }
      auto s = ck_.string(n[i], line_of(n), f);
      if (!s) continue;
      if (*s == "energy")
        model_.outputs.energy = true;
      else if (*s == "momentum")
        model_.outputs.momentum = true;
      else if (*s == "reactions")
        model_.outputs.reactions = true;
      else {
        const std::string hint = did_you_mean(*s, allowed);
        ck_.error(n[i], line_of(n), f,
                  fmt::format("unknown output '{}'{}{}expected energy, momentum, reactions or a sensor "
                              "({{name: ..., type: ..., ...}}, docs/gnc.md)", *s, hint,
                              hint.empty() ? "; " : " "));
        continue;
      }
      if (!seen.insert(*s).second) ck_.error(n[i], line_of(n), f, fmt::format("'{}' listed twice; expected it once", *s));
    }
  }

  // ---------------------------------------------------------------- bodies
  void read_bodies(const YAML::Node& bodies) {
    const int nb = static_cast<int>(bodies.size());
    info_.resize(nb);
    // Names first, so that parents named after their children are told apart
    // from unknown names.
    std::map<std::string, int> first_index;
    for (int i = 0; i < nb; ++i) {
      const YAML::Node b = bodies[i];
      BodyInfo& bi = info_[i];
      bi.line = line_of(b) ? line_of(b) : line_of(bodies);
      const std::string f = fmt::format("bodies[{}]", i);
      if (!b.IsMap()) continue;
      const YAML::Node name = b["name"];
      if (!name.IsDefined()) {
        ck_.error(bi.line, f + ".name", "missing; expected a body name matching [a-z][a-z0-9_]*");
        continue;
      }
      auto s = ck_.string(name, bi.line, f + ".name");
      if (!s) continue;
      bi.raw_name = *s;
      if (*s == "ground") {
        ck_.error(name, bi.line, f + ".name", "'ground' is reserved for the inertial frame; expected another name");
        continue;
      }
      if (!valid_body_name(*s)) {
        ck_.error(name, bi.line, f + ".name",
                  fmt::format("'{}' is not a valid body name; expected [a-z][a-z0-9_]*", *s));
        continue;
      }
      auto it = first_index.find(*s);
      if (it != first_index.end()) {
        ck_.error(name, bi.line, f + ".name",
                  fmt::format("duplicate body name '{}' (also bodies[{}]); expected unique names", *s, it->second));
        continue;
      }
      first_index[*s] = i;
      bi.name = *s;
    }
    for (int i = 0; i < nb; ++i) read_body(bodies[i], i, first_index);

    // Massless leaves with degrees of freedom.
    for (int i = 0; i < nb; ++i) {
      BodyInfo& bi = info_[i];
      if (!bi.type_known || !bi.mass_known) continue;
      if (bi.has_flex_block && !bi.flex_known) continue;
      if (bi.body.joint.type == JointType::fixed) continue;
      double mass = bi.body.rigid.mass;
      if (bi.body.flex)
        for (const auto& n : bi.body.flex->nodes) mass += n.mass;
      if (mass > 0) continue;
      bool has_children = false;
      for (int j = 0; j < nb; ++j)
        if (j != i && !bi.name.empty() && info_[j].parent_name == bi.name) has_children = true;
      if (has_children) continue;
      ck_.error(bi.mass_line ? bi.mass_line : bi.line, fmt::format("bodies[{}].mass", i),
                fmt::format("body '{}' has zero mass and no children, but its {} joint has degrees of freedom; "
                            "expected mass > 0, a fixed joint, or children",
                            bi.name, to_string(bi.body.joint.type)));
    }
  }

  void read_body(const YAML::Node& b, int i, const std::map<std::string, int>& first_index) {
    BodyInfo& bi = info_[i];
    const std::string f = fmt::format("bodies[{}]", i);
    const int l = bi.line;
    if (!ck_.expect_map(b, l, f)) {
      bi.mass_known = false;
      return;
    }
    ck_.check_keys(b, f, {"name", "parent", "joint", "mass", "com", "inertia", "flexible"});
    bi.body.name = bi.name;

    // parent
    const YAML::Node parent = b["parent"];
    if (!parent.IsDefined()) {
      ck_.error(l, f + ".parent", "missing; expected 'ground' or the name of an earlier body");
    } else if (auto p = ck_.string(parent, l, f + ".parent")) {
      bi.parent_name = *p;
      if (*p == "ground") {
        bi.parent = -1;
      } else {
        auto it = first_index.find(*p);
        if (it != first_index.end() && it->second < i) {
          bi.parent = it->second;
        } else if (it != first_index.end() && it->second == i) {
          ck_.error(parent, l, f + ".parent",
                    fmt::format("body '{}' cannot be its own parent; expected 'ground' or an earlier body", *p));
        } else if (it != first_index.end()) {
          ck_.error(parent, l, f + ".parent",
                    fmt::format("'{}' is listed after this body (bodies[{}]); expected bodies listed parents-first{}",
                                *p, it->second, i == 0 ? " (the first body's parent is ground)" : ""));
        } else {
          std::vector<std::string> cands = {"ground"};
          for (int j = 0; j < i; ++j)
            if (!info_[j].name.empty()) cands.push_back(info_[j].name);
          const std::string hint = did_you_mean(*p, cands);
          ck_.error(parent, l, f + ".parent",
                    fmt::format("no body named '{}'{}{}expected 'ground' or an earlier body", *p, hint,
                                hint.empty() ? "; " : " "));
        }
      }
    }

    // mass data (rigid part)
    const bool flexible = b["flexible"].IsDefined();
    bi.has_flex_block = flexible;
    const YAML::Node mass = b["mass"];
    if (mass.IsDefined()) {
      bi.mass_line = line_of(mass);
      if (auto m = ck_.nonneg(mass, l, f + ".mass", "a mass"))
        bi.body.rigid.mass = *m;
      else
        bi.mass_known = false;
    } else if (!flexible) {
      ck_.error(l, f + ".mass", "missing; expected the body mass in kg (>= 0)");
      bi.mass_known = false;
    }
    if (b["com"].IsDefined()) {
      if (auto c = ck_.vec3(b["com"], l, f + ".com")) bi.body.rigid.com_B = *c;
    }
    if (b["inertia"].IsDefined()) {
      if (auto I = ck_.inertia(b["inertia"], l, f + ".inertia")) bi.body.rigid.I_c_B = *I;
    }

    if (flexible) read_flexible(b["flexible"], i, key_line(b, "flexible"));

    // joint (after the parent's flexible data is known: node ids)
    const YAML::Node joint = b["joint"];
    if (!joint.IsDefined())
      ck_.error(l, f + ".joint", "missing; expected a joint {type: revolute|prismatic|fixed|free, ...}");
    else
      read_joint(joint, i, key_line(b, "joint"));
  }

  // ----------------------------------------------------------------- joint
  /// kl: line of the `joint:` key
  void read_joint(const YAML::Node& j, int i, int kl) {
    BodyInfo& bi = info_[i];
    Joint& joint = bi.body.joint;
    const std::string f = fmt::format("bodies[{}].joint", i);
    if (!ck_.expect_map(j, bi.line, f)) return;
    const int l = kl ? kl : line_of(j);
    ck_.check_keys(j, f, {"type", "axis", "axes", "sequence", "position", "node", "rotation", "stiffness", "damping",
                          "rest", "motion", "locked"});
    std::vector<std::string> type_names;
    for (const JointTraits* t : all_joint_traits()) type_names.push_back(t->name);

    const YAML::Node type = j["type"];
    if (!type.IsDefined()) {
      ck_.error(l, f + ".type", fmt::format("missing; expected one of {}", join(type_names)));
    } else if (auto s = ck_.string(type, l, f + ".type")) {
      if (const JointTraits* t = joint_traits_named(*s)) {
        bi.type_known = true;
        joint.type = t->type;
      } else {
        const std::string hint = did_you_mean(*s, type_names);
        ck_.error(type, l, f + ".type",
                  fmt::format("unknown joint type '{}'{}{}expected one of {}", *s, hint, hint.empty() ? "; " : " ",
                              join(type_names)));
      }
    }
    if (bi.type_known) read_joint_keys(j, joint, l, f);

    // position / node
    const YAML::Node position = j["position"];
    const YAML::Node node = j["node"];
    if (position.IsDefined() && node.IsDefined()) {
      ck_.error(node, l, f + ".node",
                "both position and node given; expected one of them (position on a rigid parent, node on a "
                "flexible parent)");
    } else if (position.IsDefined()) {
      if (auto p = ck_.vec3(position, l, f + ".position")) joint.p_PJ = *p;
    } else if (node.IsDefined()) {
      read_node(node, i, f + ".node");
    }

    // rotation
    const YAML::Node rot = j["rotation"];
    if (rot.IsDefined()) {
      if (auto R = read_rotation(rot, key_line(j, "rotation"), f + ".rotation")) joint.R_PJ = *R;
    }
  }

  /// The keys of a joint entry whose type is known: axes, springs, motion (JointTraits).
  void read_joint_keys(const YAML::Node& j, Joint& joint, int l, const std::string& f) {
    const JointTraits& jt = joint_traits(joint.type);
    const std::string& tname = jt.name;
    auto types_with = [&](auto pred) {
      std::vector<std::string> names;
      for (const JointTraits* t : all_joint_traits())
        if (pred(*t)) names.push_back(t->name);
      return join(names, ", ");
    };
    auto not_allowed = [&](const char* key, const std::string& which) {
      ck_.error(j[key], l, f + "." + key,
                fmt::format("not allowed on a {} joint; expected {} only on {} joints", tname, key, which));
    };

    // axis / axes / sequence
    const YAML::Node axis = j["axis"];
    if (jt.axes == JointTraits::Axes::one) {
      if (!axis.IsDefined())
        ck_.error(l, f + ".axis", fmt::format("missing; a {} joint needs a unit 3-vector axis", tname));
      else if (auto a = ck_.unit(axis, l, f + ".axis", 3, "a unit 3-vector"))
        joint.axis_J = Vec3(*a);
    } else if (axis.IsDefined()) {
      not_allowed("axis", types_with([](const JointTraits& t) { return t.axes == JointTraits::Axes::one; }));
    }
    const YAML::Node axes = j["axes"], sequence = j["sequence"];
    if (jt.axes == JointTraits::Axes::list) {
      joint.axes_J = jt.default_axes;
      if (axes.IsDefined() && sequence.IsDefined()) {
        ck_.error(sequence, l, f + ".sequence", "both axes and sequence given; expected one of them");
      } else if (axes.IsDefined()) {
        if (!axes.IsSequence() || static_cast<int>(axes.size()) != jt.n_axes) {
          ck_.error(axes, l, f + ".axes",
                    fmt::format("got {}; expected a list of {} unit 3-vectors", describe(axes), jt.n_axes));
        } else {
          for (int k = 0; k < jt.n_axes; ++k)
            if (auto a = ck_.unit(axes[k], l, fmt::format("{}.axes[{}]", f, k), 3, "a unit 3-vector"))
              joint.axes_J[k] = Vec3(*a);
        }
      } else if (sequence.IsDefined()) {
        if (!jt.sequence) {
          not_allowed("sequence", types_with([](const JointTraits& t) { return t.sequence; }));
        } else if (auto seq = ck_.string(sequence, l, f + ".sequence")) {
          const bool ok = static_cast<int>(seq->size()) == jt.n_axes &&
                          seq->find_first_not_of("xyz") == std::string::npos;
          if (!ok)
            ck_.error(sequence, l, f + ".sequence",
                      fmt::format("'{}'; expected {} letters from x, y, z (e.g. zyx)", *seq, jt.n_axes));
          else
            for (int k = 0; k < jt.n_axes; ++k) joint.axes_J[k] = Vec3::Unit((*seq)[k] - 'x');
        }
      }
      for (int k = 0; k + 1 < jt.n_axes; ++k)
        if (std::abs(joint.axes_J[k].dot(joint.axes_J[k + 1])) >= 1.0 - 1e-6)
          ck_.error(axes.IsDefined() ? axes : sequence, l, f + (axes.IsDefined() ? ".axes" : ".sequence"),
                    fmt::format("axes {} and {} are parallel; expected consecutive axes that are not parallel "
                                "(|a{}.a{}| < 1 - 1e-6)",
                                k + 1, k + 2, k + 1, k + 2));
    } else {
      if (axes.IsDefined())
        not_allowed("axes", types_with([](const JointTraits& t) { return t.axes == JointTraits::Axes::list; }));
      if (sequence.IsDefined()) not_allowed("sequence", types_with([](const JointTraits& t) { return t.sequence; }));
    }

    // spring / damper: a number (every coordinate) or one per coordinate
    for (const char* key : {"stiffness", "damping", "rest"}) {
      const YAML::Node n = j[key];
      if (!n.IsDefined()) continue;
      const std::string fk = f + "." + key;
      const bool ball_damping = jt.damping_only && std::string(key) == "damping";
      if (jt.springs == 0 && !ball_damping) {
        if (jt.damping_only)
          ck_.error(n, l, fk, fmt::format("not allowed on a {} joint; expected damping only (a {} joint has no spring)",
                                          tname, tname));
        else
          not_allowed(key, types_with([](const JointTraits& t) { return t.springs > 0; }));
        continue;
      }
      const int count = ball_damping ? 1 : jt.springs;
      auto& target = std::string(key) == "rest" ? joint.rest : std::string(key) == "stiffness" ? joint.stiffness : joint.damping;
      auto read_one = [&](const YAML::Node& x, const std::string& fx) -> std::optional<double> {
        return std::string(key) == "rest" ? ck_.number(x, l, fx) : ck_.nonneg(x, l, fx, key);
      };
      if (n.IsSequence() && !ball_damping) {
        if (static_cast<int>(n.size()) != count) {
          ck_.error(n, l, fk,
                    fmt::format("{} entries; expected a number or a list of {} (one per coordinate: {})", n.size(),
                                count, join(std::vector<std::string>(jt.coordinates.begin(), jt.coordinates.begin() + count))));
          continue;
        }
        for (int k = 0; k < count; ++k)
          if (auto x = read_one(n[k], fmt::format("{}[{}]", fk, k))) target[k] = *x;
      } else if (auto x = read_one(n, fk)) {
        for (int k = 0; k < count; ++k) target[k] = *x;
      }
    }

    // prescribed motion
    const YAML::Node motion = j["motion"];
    if (motion.IsDefined()) {
      if (!jt.prescribable) {
        not_allowed("motion", types_with([](const JointTraits& t) { return t.prescribable; }));
      } else {
        for (const char* key : {"stiffness", "damping", "rest"})
          if (j[key].IsDefined())
            ck_.error(j[key], l, f + "." + key,
                      fmt::format("not allowed with motion: (a prescribed coordinate is no degree of freedom); "
                                  "expected either motion or {}",
                                  key));
        if (auto m = read_motion(motion, key_line(j, "motion"), f + ".motion")) joint.motion = *m;
      }
    }

    // locked from the start (model/events.hpp)
    if (const YAML::Node lk = j["locked"]; lk.IsDefined()) {
      if (auto v = ck_.boolean(lk, l, f + ".locked")) {
        if (*v && motion.IsDefined())
          ck_.error(lk, l, f + ".locked", "not allowed with motion: (a prescribed joint cannot be locked); expected "
                                          "either motion or locked");
        else if (*v && jt.nu() == 0)
          ck_.error(lk, l, f + ".locked",
                    fmt::format("not allowed on a {} joint (no degree of freedom); expected locked only on joints "
                                "with degrees of freedom",
                                tname));
        else
          joint.locked = *v;
      }
    }

  }

  /// motion: {polynomial: [...]} | {sine: {...}} | {spinup: {...}}
  std::optional<PrescribedMotion> read_motion(const YAML::Node& n, int kl, const std::string& f) {
    const std::vector<std::string> kinds = {"polynomial", "sine", "spinup"};
    const int l = kl ? kl : line_of(n);
    if (!ck_.expect_map(n, l, f)) return std::nullopt;
    ck_.check_keys(n, f, kinds);
    std::vector<std::string> given;
    for (const auto& k : kinds)
      if (n[k].IsDefined()) given.push_back(k);
    if (given.size() != 1) {
      if (given.empty() && n.size() > 0) return std::nullopt;  // only unknown keys: already reported
      ck_.error(l, f,
                given.empty() ? "empty; expected exactly one of polynomial, sine, spinup"
                              : fmt::format("{} given; expected exactly one of polynomial, sine, spinup",
                                            join(given, " and ")));
      return std::nullopt;
    }
    PrescribedMotion m;
    const YAML::Node v = n[given[0]];
    const std::string fv = f + "." + given[0];
    const int vl = key_line(n, given[0]) ? key_line(n, given[0]) : l;
    bool ok = true;
    if (given[0] == "polynomial") {
      m.kind = MotionKind::polynomial;
      if (!v.IsSequence() || v.size() < 1 || v.size() > 8) {
        ck_.error(v, vl, fv, fmt::format("got {}; expected a list of 1 to 8 coefficients [c0, c1, ...]", describe(v)));
        return std::nullopt;
      }
      for (std::size_t k = 0; k < v.size(); ++k) {
        if (auto c = ck_.number(v[k], vl, fmt::format("{}[{}]", fv, k)))
          m.coefficients.push_back(*c);
        else
          ok = false;
      }
    } else {
      if (!ck_.expect_map(v, vl, fv)) return std::nullopt;
      const bool sine = given[0] == "sine";
      m.kind = sine ? MotionKind::sine : MotionKind::spinup;
      const std::vector<std::string> keys = sine ? std::vector<std::string>{"offset", "amplitude", "frequency", "phase"}
                                                 : std::vector<std::string>{"rate", "duration", "start"};
      ck_.check_keys(v, fv, keys);
      auto field = [&](const char* key, bool required, double& out, const char* expected, bool positive) {
        const YAML::Node x = v[key];
        if (!x.IsDefined()) {
          if (required) {
            ck_.error(vl, fv + "." + key, fmt::format("missing; expected {}", expected));
            ok = false;
          }
          return;
        }
        auto val = positive ? ck_.positive(x, vl, fv + "." + key, expected) : ck_.number(x, vl, fv + "." + key);
        if (val)
          out = *val;
        else
          ok = false;
      };
      if (sine) {
        field("offset", false, m.offset, "the offset", false);
        field("amplitude", true, m.amplitude, "the amplitude (rad or m)", false);
        field("frequency", true, m.frequency_hz, "a frequency in Hz", true);
        field("phase", false, m.phase, "the phase in rad", false);
      } else {
        field("rate", true, m.rate, "the final rate (rad/s or m/s)", false);
        field("duration", true, m.duration, "a duration in s", true);
        field("start", false, m.start, "the start value", false);
      }
    }
    if (!ok) return std::nullopt;
    return m;
  }

  void read_node(const YAML::Node& node, int i, const std::string& f) {
    BodyInfo& bi = info_[i];
    const auto id = ck_.integer(node, bi.line, f);
    if (!id) return;
    if (bi.parent == -2) return;  // parent already faulty
    if (bi.parent == -1) {
      ck_.error(node, bi.line, f, "node attachment on ground; expected a flexible parent (use position on ground)");
      return;
    }
    const BodyInfo& pi = info_[bi.parent];
    if (!pi.has_flex_block) {
      ck_.error(node, bi.line, f,
                fmt::format("parent '{}' is rigid (no flexible: block); expected node only on a flexible parent, "
                            "use position instead",
                            pi.name));
      return;
    }
    if (!pi.flex_known) return;  // parent's modal data already faulty
    const FlexibleData& flex = *pi.body.flex;
    const int k = flex.node_index(static_cast<int>(*id));
    if (k < 0) {
      std::vector<std::string> ids;
      for (const auto& n : flex.nodes) ids.push_back(std::to_string(n.id));
      std::string list = ids.size() <= 12 ? join(ids) : join({ids.begin(), ids.begin() + 12}) + ", ...";
      ck_.error(node, bi.line, f,
                fmt::format("no node {} in the modal data of parent '{}' ({}); expected one of its node ids: {}", *id,
                            pi.name, flex.source, list));
      return;
    }
    bi.body.joint.node = k;
    bi.node_id = static_cast<int>(*id);
  }

  std::optional<Mat3> read_rotation(const YAML::Node& n, int fallback, const std::string& f) {
    const std::vector<std::string> forms = {"rpy", "matrix", "axis_angle", "quaternion"};
    if (!n.IsMap()) {
      ck_.error(n, fallback, f,
                fmt::format("got {}; expected one of {{rpy: [r, p, y]}}, {{matrix: [[..], [..], [..]]}}, "
                            "{{axis_angle: [[x, y, z], angle]}}, {{quaternion: [w, x, y, z]}}",
                            describe(n)));
      return std::nullopt;
    }
    ck_.check_keys(n, f, forms);
    std::vector<std::string> given;
    for (const auto& k : forms)
      if (n[k].IsDefined()) given.push_back(k);
    const int l = fallback ? fallback : line_of(n);
    if (given.size() != 1) {
      if (given.empty() && n.size() > 0) return std::nullopt;  // only unknown keys: already reported
      ck_.error(l, f,
                given.empty() ? "empty; expected exactly one of rpy, matrix, axis_angle, quaternion"
                              : fmt::format("{} given; expected exactly one of rpy, matrix, axis_angle, quaternion",
                                            join(given, " and ")));
      return std::nullopt;
    }
    const std::string form = given[0];
    const YAML::Node v = n[form];
    const std::string fv = f + "." + form;
    if (form == "rpy") {
      auto a = ck_.vec3(v, l, fv);
      if (!a) return std::nullopt;
      return rpy_R((*a)(0), (*a)(1), (*a)(2));
    }
    if (form == "matrix") {
      auto R = ck_.mat3(v, l, fv);
      if (!R) return std::nullopt;
      const double scale = R->cwiseAbs().maxCoeff();
      const double orth = (R->transpose() * *R - Mat3::Identity()).cwiseAbs().maxCoeff();
      if (!(orth <= 1e-9 * std::max(scale, 1e-300))) {
        ck_.error(v, l, fv,
                  fmt::format("not orthonormal (largest |R^T R - I| entry {}); expected a rotation matrix "
                              "(orthonormal to 1e-9, determinant +1)",
                              num(orth)));
        return std::nullopt;
      }
      const double det = R->determinant();
      if (std::abs(det - 1.0) > 1e-9 * scale * scale * scale) {
        ck_.error(v, l, fv,
                  fmt::format("determinant {} (a reflection); expected a proper rotation with determinant +1",
                              num(det)));
        return std::nullopt;
      }
      return *R;
    }
    if (form == "axis_angle") {
      if (!v.IsSequence() || v.size() != 2) {
        ck_.error(v, l, fv, fmt::format("got {}; expected [[x, y, z], angle]", describe(v)));
        return std::nullopt;
      }
      auto a = ck_.unit(v[0], line_of(v), fv + "[0]", 3, "a unit 3-vector axis");
      auto angle = ck_.number(v[1], line_of(v), fv + "[1]");
      if (!a || !angle) return std::nullopt;
      return axis_angle_R<double>(Vec3(*a), *angle);
    }
    // quaternion
    auto q = ck_.unit(v, l, fv, 4, "a unit quaternion [w, x, y, z]");
    if (!q) return std::nullopt;
    return quat_to_R<double>(Eigen::Vector4d(*q));
  }

  // -------------------------------------------------------------- flexible
  /// kl: line of the `flexible:` key
  void read_flexible(const YAML::Node& n, int i, int kl) {
    BodyInfo& bi = info_[i];
    const std::string f = fmt::format("bodies[{}].flexible", i);
    if (!ck_.expect_map(n, bi.line, f)) return;
    const int l = kl ? kl : line_of(n);
    ck_.check_keys(n, f, {"modal", "beam", "damping_ratio", "modes", "foreshortening"});
    bool foreshortening = true;
    if (n["foreshortening"].IsDefined()) {
      if (auto b = ck_.boolean(n["foreshortening"], l, f + ".foreshortening")) foreshortening = *b;
    }

    // modes subset (validated before the data, range checked after)
    std::vector<int> keep;
    std::vector<int> keep_line;
    bool keep_ok = true;
    const YAML::Node modes = n["modes"];
    if (modes.IsDefined()) {
      if (!ck_.expect_seq(modes, l, f + ".modes") || modes.size() == 0) {
        if (modes.IsSequence()) ck_.error(modes, l, f + ".modes", "empty; expected a list of 1-based mode numbers");
        keep_ok = false;
      } else {
        for (std::size_t k = 0; k < modes.size(); ++k) {
          const std::string fk = fmt::format("{}.modes[{}]", f, k);
          auto m = ck_.integer(modes[k], line_of(modes), fk);
          if (!m) {
            keep_ok = false;
            continue;
          }
          if (*m < 1) {
            ck_.error(modes[k], line_of(modes), fk, fmt::format("{} is not a mode number; expected 1-based mode numbers (>= 1)", *m));
            keep_ok = false;
            continue;
          }
          if (std::find(keep.begin(), keep.end(), static_cast<int>(*m)) != keep.end()) {
            ck_.error(modes[k], line_of(modes), fk, fmt::format("mode {} listed twice; expected unique mode numbers", *m));
            keep_ok = false;
            continue;
          }
          keep.push_back(static_cast<int>(*m));
          keep_line.push_back(line_of(modes[k]) ? line_of(modes[k]) : line_of(modes));
        }
      }
    }

    const YAML::Node modal = n["modal"];
    const YAML::Node beam = n["beam"];
    std::optional<FlexibleData> data;
    const std::size_t before = diags_.size();
    if (modal.IsDefined() && beam.IsDefined()) {
      ck_.error(beam, l, f + ".beam", "both modal and beam given; expected exactly one of them");
    } else if (!modal.IsDefined() && !beam.IsDefined()) {
      ck_.error(l, f, "no modal data; expected 'modal: FILE.modal.yaml' or a 'beam:' block");
    } else if (modal.IsDefined()) {
      if (auto s = ck_.string(modal, l, f + ".modal")) {
        namespace fs = std::filesystem;
        const fs::path rel(*s);
        const std::string resolved =
            rel.is_absolute() ? rel.string() : (fs::path(path_).parent_path() / rel).string();
        std::error_code ec;
        if (!fs::is_regular_file(resolved, ec)) {
          ck_.error(modal, l, f + ".modal",
                    fmt::format("cannot open modal file '{}'; expected a modal data file (path relative to the "
                                "model file)",
                                resolved));
        } else {
          FlexibleData d = load_modal_file(resolved, {}, diags_);
          if (diags_.size() == before) data = std::move(d);
        }
      }
    } else {
      auto spec = read_beam(beam, f + ".beam", key_line(n, "beam"));
      if (spec) spec->second_order = foreshortening;
      // the foreshortening data are elements x modes^2 numbers: refuse before computing them
      if (spec && foreshortening &&
          static_cast<double>(spec->elements) * spec->modes * spec->modes > kMaxSecondOrderEntries) {
        ck_.error(beam, l, f + ".beam",
                  fmt::format("{} elements x {} modes^2 = {:.3g} foreshortening numbers; expected at most {:.3g} "
                              "(fewer elements or modes, or foreshortening: false; docs/limits.md)",
                              spec->elements, spec->modes,
                              static_cast<double>(spec->elements) * spec->modes * spec->modes,
                              kMaxSecondOrderEntries));
        spec.reset();
      }
      if (spec) {
        try {
          data = beam_modal_data(*spec);
          data->source = "beam";
        } catch (const std::exception& e) {
          ck_.error(beam, l, f + ".beam", fmt::format("cannot compute the beam modes: {}", e.what()));
        }
      }
    }

    // subset
    if (data && keep_ok && !keep.empty()) {
      bool in_range = true;
      for (std::size_t k = 0; k < keep.size(); ++k) {
        if (keep[k] > data->modes()) {
          ck_.error(keep_line[k], fmt::format("{}.modes[{}]", f, k),
                    fmt::format("mode {} does not exist: {} has {} modes; expected mode numbers in 1..{}", keep[k],
                                data->source, data->modes(), data->modes()));
          in_range = false;
        }
      }
      if (in_range) {
        std::vector<int> sel;
        for (int k : keep) sel.push_back(k - 1);
        data = select_modes(*data, sel);
      } else {
        data.reset();
      }
    } else if (!keep_ok) {
      data.reset();
    }
    if (data && data->modes() > kMaxBodyModes) {
      ck_.error(l, f, fmt::format("{} modes kept; expected at most {} per body (choose them with modes: [...]; "
                                  "docs/limits.md)",
                                  data->modes(), kMaxBodyModes));
      data.reset();
    }

    // damping ratios
    const int m = data ? data->modes() : -1;
    Eigen::VectorXd zeta = Eigen::VectorXd::Zero(std::max(m, 0));
    bool zeta_ok = true;
    const YAML::Node dr = n["damping_ratio"];
    const std::string fd = f + ".damping_ratio";
    if (dr.IsDefined()) {
      if (dr.IsSequence()) {
        Eigen::VectorXd z(dr.size());
        for (std::size_t k = 0; k < dr.size(); ++k) {
          if (auto x = ck_.nonneg(dr[k], line_of(dr), fmt::format("{}[{}]", fd, k), "a damping ratio"))
            z(k) = *x;
          else
            zeta_ok = false;
        }
        if (m >= 0 && static_cast<int>(dr.size()) != m) {
          ck_.error(dr, l, fd,
                    fmt::format("{} values for {} kept modes; expected a number or one value per kept mode",
                                dr.size(), m));
          zeta_ok = false;
        } else if (zeta_ok && m >= 0) {
          zeta = z;
        }
      } else if (auto x = ck_.nonneg(dr, l, fd, "a damping ratio")) {
        zeta.setConstant(*x);
      } else {
        zeta_ok = false;
      }
    }

    if (!data || !zeta_ok) return;
    FlexibleData& fd_ = *data;
    if (!foreshortening) fd_.Gamma.assign(fd_.nodes.size(), {});
    fd_.damping_ratio = zeta;
    fd_.K = Eigen::VectorXd::Zero(m);
    fd_.D = Eigen::VectorXd::Zero(m);
    const Eigen::VectorXd Y = modal_masses(fd_);  // with the nodes' rotary inertia (dynamics.md)
    for (int c = 0; c < m; ++c) {
      const double w = 2.0 * std::numbers::pi * fd_.frequency_hz(c);
      fd_.K(c) = w * w * Y(c);
      fd_.D(c) = 2.0 * zeta(c) * w * Y(c);
    }
    bi.body.flex = std::move(fd_);
    bi.flex_known = true;
  }

  std::optional<BeamSpec> read_beam(const YAML::Node& n, const std::string& f, int kl) {
    if (!ck_.expect_map(n, kl, f)) return std::nullopt;
    const int l = kl ? kl : line_of(n);
    ck_.check_keys(n, f, {"length", "direction", "mass_per_length", "EI", "GJ", "EA", "elements", "modes",
                          "rotary_inertia_per_length", "polar_inertia_per_length"});
    BeamSpec spec;
    bool ok = true;
    auto required = [&](const char* key, const char* expected) -> YAML::Node {
      const YAML::Node v = n[key];
      if (!v.IsDefined()) {
        ck_.error(l, f + "." + key, fmt::format("missing; expected {}", expected));
        ok = false;
      }
      return v;
    };
    if (auto v = required("length", "the beam length in m (> 0)"); v.IsDefined()) {
      if (auto x = ck_.positive(v, l, f + ".length", "a length"))
        spec.length = *x;
      else
        ok = false;
    }
    if (auto v = required("direction", "one of x, y, z, -x, -y, -z"); v.IsDefined()) {
      const std::vector<std::string> dirs = {"x", "y", "z", "-x", "-y", "-z"};
      if (auto s = ck_.string(v, l, f + ".direction")) {
        auto it = std::find(dirs.begin(), dirs.end(), *s);
        if (it == dirs.end()) {
          ck_.error(v, l, f + ".direction", fmt::format("'{}' is not a direction; expected one of x, y, z, -x, -y, -z", *s));
          ok = false;
        } else {
          const int k = static_cast<int>(it - dirs.begin());
          spec.axis = k % 3;
          spec.sign = k < 3 ? 1 : -1;
        }
      } else {
        ok = false;
      }
    }
    if (auto v = required("mass_per_length", "the mass per length in kg/m (> 0)"); v.IsDefined()) {
      if (auto x = ck_.positive(v, l, f + ".mass_per_length", "a mass per length"))
        spec.mass_per_length = *x;
      else
        ok = false;
    }
    if (auto v = required("EI", "two bending stiffnesses [EI1, EI2] in N·m² (> 0)"); v.IsDefined()) {
      if (auto e = ck_.vector(v, l, f + ".EI", 2)) {
        for (int k = 0; k < 2; ++k) {
          if (!((*e)(k) > 0)) {
            ck_.error(v, l, fmt::format("{}.EI[{}]", f, k),
                      fmt::format("{} is not positive; expected a bending stiffness > 0", num((*e)(k))));
            ok = false;
          }
          spec.EI[k] = (*e)(k);
        }
      } else {
        ok = false;
      }
    }
    for (const char* key : {"GJ", "EA"}) {
      const YAML::Node v = n[key];
      if (!v.IsDefined()) continue;
      if (auto x = ck_.positive(v, l, f + "." + key, key))
        (std::string(key) == "GJ" ? spec.GJ : spec.EA) = *x;
      else
        ok = false;
    }
    if (const YAML::Node v = n["rotary_inertia_per_length"]; v.IsDefined()) {
      if (auto e = ck_.vector(v, l, f + ".rotary_inertia_per_length", 2)) {
        for (int k = 0; k < 2; ++k) {
          if (!((*e)(k) >= 0)) {
            ck_.error(v, l, fmt::format("{}.rotary_inertia_per_length[{}]", f, k),
                      fmt::format("{} is negative; expected a rotary inertia per length >= 0 (kg m)", num((*e)(k))));
            ok = false;
          }
          spec.rotary_inertia[k] = (*e)(k);
        }
      } else {
        ok = false;
      }
    }
    if (const YAML::Node v = n["polar_inertia_per_length"]; v.IsDefined()) {
      if (auto x = ck_.nonneg(v, l, f + ".polar_inertia_per_length", "a polar inertia per length (kg m)"))
        spec.polar_inertia = *x;
      else
        ok = false;
    }
    for (const char* key : {"elements", "modes"}) {
      const YAML::Node v = required(key, std::string(key) == "elements" ? "the number of finite elements (>= 1)"
                                                                         : "the number of modes kept (>= 1)");
      if (!v.IsDefined()) continue;
      auto x = ck_.integer(v, l, f + "." + key);
      if (!x) {
        ok = false;
      } else if (*x < 1 || *x > (std::string(key) == "elements" ? kMaxBeamElements : kMaxBodyModes)) {
        ck_.error(v, l, f + "." + key,
                  fmt::format("{} is out of range; expected an integer in 1..{} (docs/limits.md)", *x,
                              std::string(key) == "elements" ? kMaxBeamElements : kMaxBodyModes));
        ok = false;
      } else {
        (std::string(key) == "elements" ? spec.elements : spec.modes) = static_cast<int>(*x);
      }
    }
    if (!ok) return std::nullopt;
    return spec;
  }

  // --------------------------------------------------------------- initial
  /// Names of the coordinates (q) or speeds (u) of body i; `certain` is false
  /// when the body's faults leave its names unknown.
  std::vector<std::string> body_names(int i, bool speeds, bool& certain) const {
    const BodyInfo& bi = info_[i];
    std::vector<std::string> names;
    certain = !bi.name.empty() && bi.type_known && (!bi.has_flex_block || bi.flex_known);
    if (bi.name.empty()) return names;
    const std::string& n = bi.name;
    if (bi.type_known && !bi.body.joint.prescribed()) {
      const JointTraits& jt = joint_traits(bi.body.joint.type);
      for (const auto& c : speeds ? jt.speeds : jt.coordinates) names.push_back(n + "." + c);
    }
    if (bi.body.flex)
      for (int k = 1; k <= bi.body.flex->modes(); ++k)
        names.push_back(n + ".eta" + std::to_string(k) + (speeds ? "_rate" : ""));
    return names;
  }

  /// Whether `name` is the coordinate of a prescribed joint (e.g. "hub.angle").
  bool prescribed_coordinate(const std::string& name) const {
    for (const BodyInfo& bi : info_)
      if (!bi.name.empty() && bi.type_known && bi.body.joint.prescribed() &&
          name == bi.name + "." + joint_traits(bi.body.joint.type).coordinates[0])
        return true;
    return false;
  }

  /// `gravity:` a uniform field [gx, gy, gz] or {central: {mu, J2, radius}} (model-format.md, "Gravity").
  void read_gravity(const YAML::Node& g) {
    if (!g.IsMap()) {
      if (auto v = ck_.vec3(g, 1, "gravity")) model_.g_N = *v;
      return;
    }
    ck_.check_keys(g, "gravity", {"central"});
    const YAML::Node c = g["central"];
    if (!c.IsDefined()) {
      ck_.error(g, 1, "gravity", "a mapping without 'central'; expected [gx, gy, gz] or {central: {mu: ...}}");
      return;
    }
    if (!ck_.expect_map(c, line_of(g), "gravity.central")) return;
    const int l = line_of(c) ? line_of(c) : line_of(g);
    ck_.check_keys(c, "gravity.central", {"mu", "J2", "radius"});
    CentralGravity cg;
    bool ok = true;
    if (!c["mu"].IsDefined()) {
      ck_.error(c, l, "gravity.central.mu", "missing; expected the gravitational parameter mu > 0 (m^3/s^2)");
      ok = false;
    } else if (auto mu = ck_.positive(c["mu"], l, "gravity.central.mu", "mu")) {
      cg.mu = *mu;
    } else {
      ok = false;
    }
    const bool j2 = c["J2"].IsDefined(), radius = c["radius"].IsDefined();
    if (j2 != radius) {
      ck_.error(c, l, j2 ? "gravity.central.radius" : "gravity.central.J2",
                "missing; J2 and radius are given together (J2 is relative to the body's radius)");
      ok = false;
    } else if (j2) {
      if (auto v = ck_.number(c["J2"], l, "gravity.central.J2")) cg.J2 = *v;
      else ok = false;
      if (auto v = ck_.positive(c["radius"], l, "gravity.central.radius", "the central body's radius")) cg.radius = *v;
      else ok = false;
    }
    if (ok) {
      model_.central = cg;
      central_line_ = l;
    }
  }

  /// `initial: orbit: {a, e, i, raan, argp, nu, attitude: lvlh, attitude_offset, rate_offset}` (checked against the rest in build()).
  void read_orbit(const YAML::Node& o, int fallback) {
    if (!ck_.expect_map(o, fallback, "initial.orbit")) return;
    const int l = line_of(o) ? line_of(o) : fallback;
    ck_.check_keys(o, "initial.orbit",
                   {"a", "e", "i", "raan", "argp", "nu", "attitude", "attitude_offset", "rate_offset"});
    InitialOrbit orb;
    bool ok = true;
    auto get = [&](const char* key, double& out, bool required) {
      const std::string f = std::string("initial.orbit.") + key;
      if (!o[key].IsDefined()) {
        if (required) {
          ck_.error(o, l, f, "missing; expected the orbit's semi-major axis a (m) and eccentricity e");
          ok = false;
        }
        return;
      }
      if (auto v = ck_.number(o[key], l, f)) out = *v;
      else ok = false;
    };
    get("a", orb.elements.a, true);
    get("e", orb.elements.e, true);
    get("i", orb.elements.i, false);
    get("raan", orb.elements.raan, false);
    get("argp", orb.elements.argp, false);
    get("nu", orb.elements.nu, false);
    if (ok && !(orb.elements.a > 0)) {
      ck_.error(o["a"], l, "initial.orbit.a", fmt::format("{} is not positive; expected a > 0 (m)", orb.elements.a));
      ok = false;
    }
    if (ok && !(orb.elements.e >= 0 && orb.elements.e < 1)) {
      ck_.error(o["e"], l, "initial.orbit.e",
                fmt::format("{}; expected 0 <= e < 1 (an elliptic orbit)", orb.elements.e));
      ok = false;
    }
    if (o["attitude"].IsDefined()) {
      auto a = ck_.string(o["attitude"], l, "initial.orbit.attitude");
      if (a && *a != "lvlh") {
        ck_.error(o["attitude"], l, "initial.orbit.attitude", fmt::format("'{}'; expected lvlh", *a));
        ok = false;
      }
      orb.lvlh = a && *a == "lvlh";
    }
    // the root's attitude and rate relative to the orbit frame (model-format.md, Gravity): with lvlh only
    for (const char* key : {"attitude_offset", "rate_offset"}) {
      if (!o[key].IsDefined()) continue;
      const std::string f = std::string("initial.orbit.") + key;
      const int kl = line_of(o[key]) ? line_of(o[key]) : l;
      if (!orb.lvlh) {
        ck_.error(o[key], kl, f, "given without attitude: lvlh; expected attitude: lvlh (the offset is from the orbit frame)");
        ok = false;
        continue;
      }
      if (std::string(key) == "attitude_offset") {
        if (auto R = read_rotation(o[key], kl, f)) orb.R_LB = *R;
        else ok = false;
      } else if (auto w = ck_.vec3(o[key], kl, f)) {
        orb.rate_offset_B = *w;
      } else {
        ok = false;
      }
    }
    if (ok) {
      orb.line = l;
      orbit_ = orb;
      orbit_line_ = l;
    }
  }

  /// The orbit's free root body, with what it asks of the model and of the rest of `initial:`; -1 with faults.
  int orbit_root() {
    if (!model_.central) {
      ck_.error(orbit_line_, "initial.orbit", "an orbit needs a central field; expected gravity: {central: {mu: ...}}");
      return -1;
    }
    int root = -1, roots = 0;
    for (std::size_t i = 0; i < model_.bodies.size(); ++i)
      if (model_.bodies[i].parent < 0) ++roots, root = static_cast<int>(i);
    if (roots != 1 || model_.bodies[root].joint.type != JointType::free) {
      ck_.error(orbit_line_, "initial.orbit",
                fmt::format("an orbit places one free root body; the model has {} root bodies{}", roots,
                            roots == 1 ? " and its joint is not free" : ""));
      return -1;
    }
    const std::string& b = model_.bodies[root].name;
    const OrbitSetNames set = orbit_set_names(b, orbit_->lvlh);
    const std::vector<std::string>&q_set = set.q, &u_set = set.u;
    bool ok = true;
    for (auto [set, given] : {std::pair{&q_set, &init_q_}, std::pair{&u_set, &init_u_}})
      for (const std::string& n : *set)
        if (auto it = given->find(n); it != given->end()) {
          ck_.error(it->second.line, (given == &init_q_ ? "initial.q." : "initial.u.") + n,
                    fmt::format("'{}' is set by initial.orbit (line {}){}; expected one of them", n, orbit_line_,
                                orbit_->lvlh ? " with attitude: lvlh" : ""));
          ok = false;
        }
    return ok ? root : -1;
  }

  void read_initial(const YAML::Node& n) {
    if (!ck_.expect_map(n, 1, "initial")) return;
    ck_.check_keys(n, "initial", {"q", "u", "orbit"});
    if (n["orbit"].IsDefined()) read_orbit(n["orbit"], line_of(n));
    for (const bool speeds : {false, true}) {
      const char* key = speeds ? "u" : "q";
      const YAML::Node m = n[key];
      if (!m.IsDefined()) continue;
      const std::string f = std::string("initial.") + key;
      if (!ck_.expect_map(m, line_of(n), f)) continue;
      std::vector<std::string> known;
      std::vector<std::string> uncertain_prefix;
      for (int i = 0; i < static_cast<int>(info_.size()); ++i) {
        bool certain = true;
        auto names = body_names(i, speeds, certain);
        known.insert(known.end(), names.begin(), names.end());
        // names of a faulty body are unknown: do not report them again
        if (!certain && !info_[i].raw_name.empty()) uncertain_prefix.push_back(info_[i].raw_name + ".");
      }
      auto& given = speeds ? init_u_ : init_q_;
      for (auto it = m.begin(); it != m.end(); ++it) {
        const int kl = line_of(it->first) ? line_of(it->first) : line_of(m);
        if (!it->first.IsScalar()) {
          ck_.error(kl, f, "a key must be a coordinate name");
          continue;
        }
        std::string name = it->first.Scalar();
        const std::string fk = f + "." + name;
        auto x = ck_.number(it->second, kl, fk);
        // an older speed name (a coordinate's name for its rate) means the rate
        if (speeds && std::find(known.begin(), known.end(), name) == known.end() &&
            std::find(known.begin(), known.end(), name + "_rate") != known.end())
          name += "_rate";
        if (std::find(known.begin(), known.end(), name) == known.end()) {
          if (prescribed_coordinate(name)) {
            ck_.error(kl, fk,
                      fmt::format("'{}' is prescribed by its joint's motion: (a known function of time); expected "
                                  "no initial value for it",
                                  name));
            continue;
          }
          bool uncertain = false;
          for (const auto& p : uncertain_prefix)
            if (name.rfind(p, 0) == 0) uncertain = true;
          if (!uncertain)
            ck_.error(kl, fk,
                      fmt::format("unknown {} name '{}'{}{}expected one of: {}", speeds ? "speed" : "coordinate", name,
                                  did_you_mean(name, known), did_you_mean(name, known).empty() ? "; " : " ",
                                  known.empty() ? "(none)" : join(known)));
          continue;
        }
        if (given.count(name)) {
          ck_.error(kl, fk, fmt::format("'{}' given twice (also under its older or newer name); expected it once", name));
          continue;
        }
        if (x) given[name] = Given{*x, kl};
      }
      if (speeds) continue;
      // quaternions: all four components or none; unit to 1e-6
      for (const BodyInfo& bi : info_) {
        if (bi.name.empty() || !bi.type_known || !joint_traits(bi.body.joint.type).has_quaternion()) continue;
        const JointTraits& jt = joint_traits(bi.body.joint.type);
        std::vector<std::string> comp, have, lack;
        for (int k = 0; k < 4; ++k) {
          comp.push_back(bi.name + "." + jt.coordinates[jt.quaternion + k]);
          (given.count(comp.back()) ? have : lack).push_back(comp.back());
        }
        if (have.empty()) continue;
        const int ql = given[have[0]].line;
        if (!lack.empty()) {
          ck_.error(ql, f + "." + have[0],
                    fmt::format("quaternion of '{}' given in part ({} missing); expected all of {} or none", bi.name,
                                join(lack), join(comp)));
          for (const auto& c : have) given.erase(c);
          continue;
        }
        Eigen::Vector4d q;
        for (int k = 0; k < 4; ++k) q(k) = given[comp[k]].value;
        const double nrm = q.norm();
        if (std::abs(nrm - 1.0) > 1e-6) {
          ck_.error(ql, f + "." + have[0],
                    fmt::format("quaternion of '{}' has norm {}; expected a unit quaternion (norm 1 to within 1e-6)",
                                bi.name, num(nrm)));
          continue;
        }
        for (int k = 0; k < 4; ++k) given[comp[k]].value = q(k) / nrm;
      }
    }
  }

  /// The engines hold nu x nu matrices and factor them: refuse a model whose
  /// speeds (joint coordinates and modes) exceed kMaxSpeeds before building it.
  void check_speed_count(const YAML::Node& bodies) {
    long nu = 0;
    for (const BodyInfo& bi : info_) {
      const Joint& j = bi.body.joint;
      if (bi.type_known) nu += joint_nu(j);
      if (bi.body.flex) nu += bi.body.flex->modes();
    }
    if (nu > kMaxSpeeds)
      ck_.error(bodies, 1, "bodies",
                fmt::format("{} generalized speeds (joint coordinates and modes); expected at most {} "
                            "(docs/limits.md)",
                            nu, kMaxSpeeds));
  }

  /// A central field acts on a free system: every root joint free (a body fixed to N would sit in the field).
  void check_central_roots() {
    if (!model_.central) return;
    for (std::size_t i = 0; i < info_.size(); ++i)
      if (const BodyInfo& bi = info_[i]; bi.parent == -1 && bi.type_known && bi.body.joint.type != JointType::free)
        ck_.error(bi.line, fmt::format("bodies[{}].joint.type", i),
                  fmt::format("'{}' joint to ground under a central gravity field (line {}); expected a free root "
                              "joint (the spacecraft orbits the central body)",
                              to_string(bi.body.joint.type), central_line_));
  }

  // ----------------------------------------------------------------- build
  Model build() {
    for (BodyInfo& bi : info_) {
      bi.body.parent = bi.parent;
      bi.body.line = bi.line;
      snap_roundoff_residues(bi.body);
      model_.bodies.push_back(std::move(bi.body));
    }
    snap_roundoff_residues(model_.g_N);
    finalize_model(model_);
    model_.q0 = VecX::Zero(model_.nq);
    model_.u0 = VecX::Zero(model_.nu);
    for (const auto& slot : model_.quaternions) model_.q0(slot.q) = 1.0;
    for (const auto& [name, g] : init_q_) {
      const int k = model_.q_index(name);
      if (k >= 0) model_.q0(k) = g.value;
    }
    for (const auto& [name, g] : init_u_) {
      const int k = model_.speed_index(name);
      if (k >= 0) model_.u0(k) = g.value;
    }
    if (orbit_)
      if (const int root = orbit_root(); root >= 0) {
        model_.initial_orbit = *orbit_;  // placed by engine/load_model.hpp's load_model()
        model_.orbit_root = root;
      }
    std::vector<Diagnostic> bad(diags_.begin(), diags_.end());  // the orbit's faults
    for (std::size_t i = 0; i < parameter_names_.size(); ++i) {
      const auto& [name, line] = parameter_names_[i];
      try {
        for (RuntimeParameter& p : expand_parameter(model_, name)) {
          if (find_parameter(model_.parameters, p.kind, p.body, p.index) >= 0)
            throw std::invalid_argument(fmt::format("'{}' is named twice", p.name));
          model_.parameters.push_back(p);
        }
      } catch (const std::invalid_argument& e) {
        bad.push_back(Diagnostic{path_, line, fmt::format("parameters[{}]", i), e.what()});
      }
    }
    if (has_events_) read_events(events_, path_, model_, bad);
    // a joint locked from the start holds its speeds at zero (dynamics.md, Locks)
    for (const Body& b : model_.bodies) {
      if (!b.joint.locked) continue;
      for (int k = 0; k < joint_nu(b.joint); ++k) {
        const std::string& un = model_.u_names[b.u_joint + k];
        auto it = init_u_.find(un);
        if (it != init_u_.end() && it->second.value != 0.0)
          bad.push_back(Diagnostic{path_, it->second.line, "initial.u." + un,
                                   fmt::format("{} for a speed of '{}', whose joint is locked: true; expected 0 or "
                                               "none (a locked joint does not move)",
                                               num(it->second.value), b.name)});
      }
    }
    if (!bad.empty()) {
      std::sort(bad.begin(), bad.end(), [](const Diagnostic& a, const Diagnostic& b) { return a.line < b.line; });
      throw InputError(bad);
    }
    return std::move(model_);
  }
};

}  // namespace

Model parse_model(const std::string& path) { return Loader(path).load(); }

}  // namespace kanegen
