#include "model/events.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <map>
#include <set>

#include "model/diagnostics.hpp"
#include "model/model.hpp"
#include "model/yaml_check.hpp"

namespace kanegen {

using namespace yamlcheck;

bool joint_can_lock(const Joint& j) { return !j.prescribed() && joint_nu(j) > 0; }

LockSet initial_locks(const Model& model) {
  LockSet s(model.bodies.size(), 0);
  for (std::size_t i = 0; i < model.bodies.size(); ++i) s[i] = model.bodies[i].joint.locked ? 1 : 0;
  return s;
}

bool any_locked(const LockSet& locks) {
  return std::any_of(locks.begin(), locks.end(), [](char c) { return c != 0; });
}

std::vector<int> locked_speeds(const Model& model, const LockSet& locks) {
  std::vector<int> out;
  for (std::size_t i = 0; i < model.bodies.size() && i < locks.size(); ++i)
    if (locks[i]) {
      const Body& b = model.bodies[i];
      for (int k = 0; k < joint_nu(b.joint); ++k) out.push_back(b.u_joint + k);
    }
  std::sort(out.begin(), out.end());
  return out;
}

int joint_body_of_speed(const Model& model, int k) {
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const Body& b = model.bodies[i];
    if (k >= b.u_joint && k < b.u_joint + joint_nu(b.joint)) return static_cast<int>(i);
  }
  return -1;
}

int joint_body_of_coordinate(const Model& model, int k) {
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const Body& b = model.bodies[i];
    if (k >= b.q_joint && k < b.q_joint + joint_nq(b.joint)) return static_cast<int>(i);
  }
  return -1;
}

namespace {

/// The bodies of `lock:` / `release:` (a list of body names), each one whose joint can lock.
std::vector<int> read_bodies(const YAML::Node& n, int l, const std::string& f, const Model& model, Checker& ck) {
  std::vector<int> out;
  if (!n.IsSequence()) {
    ck.error(n, l, f, fmt::format("got {}; expected a list of body names", describe(n)));
    return out;
  }
  if (n.size() == 0) {
    ck.error(n, l, f, "an empty list; expected at least one body name (leave the key out for no such action)");
    return out;
  }
  std::vector<std::string> names;
  for (const Body& b : model.bodies) names.push_back(b.name);
  for (std::size_t k = 0; k < n.size(); ++k) {
    const std::string fk = fmt::format("{}[{}]", f, k);
    auto s = ck.string(n[k], l, fk);
    if (!s) continue;
    const int b = model.body_index(*s);
    if (b < 0) {
      ck.error(n[k], l, fk, fmt::format("no body named '{}'{}", *s, did_you_mean(*s, names)));
      continue;
    }
    const Joint& j = model.bodies[b].joint;
    if (j.prescribed()) {
      ck.error(n[k], l, fk,
               fmt::format("the joint of '{}' is prescribed (motion:); expected a body whose joint has degrees of "
                           "freedom (a prescribed joint cannot be locked)",
                           *s));
      continue;
    }
    if (!joint_can_lock(j)) {
      ck.error(n[k], l, fk,
               fmt::format("the joint of '{}' is {} (no degree of freedom); expected a body whose joint has degrees "
                           "of freedom",
                           *s, to_string(j.type)));
      continue;
    }
    if (std::find(out.begin(), out.end(), b) != out.end()) {
      ck.error(n[k], l, fk, fmt::format("'{}' named twice; expected each body once", *s));
      continue;
    }
    out.push_back(b);
  }
  return out;
}

}  // namespace

void read_events(const YAML::Node& events, const std::string& path, Model& model, std::vector<Diagnostic>& faults) {
  Checker ck(path, faults);
  if (!ck.expect_seq(events, 1, "events")) return;
  std::set<std::string> seen;
  std::vector<bool> entry_ok;
  for (std::size_t i = 0; i < events.size(); ++i) {
    const YAML::Node e = events[i];
    const std::string f = fmt::format("events[{}]", i);
    const int l = line_of(e) ? line_of(e) : line_of(events);
    if (!ck.expect_map(e, l, f)) continue;
    const std::size_t before = faults.size();
    ck.check_keys(e, f, {"name", "at", "when", "lock", "release"});
    Event ev;
    ev.line = l;
    const YAML::Node name = e["name"];
    if (!name.IsDefined()) {
      ck.error(l, f + ".name", "missing; expected a name matching [a-z][a-z0-9_]*");
    } else if (auto s = ck.string(name, l, f + ".name")) {
      if (!valid_identifier(*s))
        ck.error(name, l, f + ".name",
                 fmt::format("'{}'; expected a name matching [a-z][a-z0-9_]* (at most 64 characters)", *s));
      else if (!seen.insert(*s).second)
        ck.error(name, l, f + ".name", fmt::format("'{}' is the name of an earlier event; expected a unique name", *s));
      else
        ev.name = *s;
    }
    const YAML::Node at = e["at"], when = e["when"];
    if (at.IsDefined() == when.IsDefined()) {
      ck.error(l, f, at.IsDefined() ? "both at: and when: given; expected one trigger"
                                    : "no trigger; expected at: TIME or when: {coordinate: NAME, reaches: VALUE}");
    } else if (at.IsDefined()) {
      ev.trigger = Event::Trigger::time;
      if (auto t = ck.nonneg(at, l, f + ".at", "the event time")) ev.at = *t;
    } else if (ck.expect_map(when, l, f + ".when")) {
      ev.trigger = Event::Trigger::crossing;
      ck.check_keys(when, f + ".when", {"coordinate", "reaches"});
      const YAML::Node c = when["coordinate"], r = when["reaches"];
      if (!c.IsDefined()) {
        ck.error(l, f + ".when.coordinate", "missing; expected the name of a coordinate (q)");
      } else if (auto s = ck.string(c, l, f + ".when.coordinate")) {
        ev.coordinate = model.q_index(*s);
        for (const auto& slot : model.quaternions)
          if (ev.coordinate >= slot.q && ev.coordinate < slot.q + 4)
            ck.error(c, l, f + ".when.coordinate",
                     fmt::format("'{}' is a component of a unit quaternion (a free or ball joint's attitude: its "
                                 "value is no angle, and q and -q are the same attitude); expected a joint angle or "
                                 "position, or a modal coordinate",
                                 *s));
        if (ev.coordinate < 0) {
          const bool prescribed = std::find(model.prescribed_names.begin(), model.prescribed_names.end(), *s) !=
                                  model.prescribed_names.end();
          if (prescribed)
            ck.error(c, l, f + ".when.coordinate",
                     fmt::format("'{}' is prescribed by its joint's motion: (a known function of time); expected a "
                                 "coordinate of a degree of freedom",
                                 *s));
          else
            ck.error(c, l, f + ".when.coordinate",
                     fmt::format("unknown coordinate '{}'{}{}expected one of: {}", *s, did_you_mean(*s, model.q_names),
                                 did_you_mean(*s, model.q_names).empty() ? "; " : " ", join(model.q_names)));
        }
      }
      if (!r.IsDefined())
        ck.error(l, f + ".when.reaches", "missing; expected the value whose crossing fires the event");
      else if (auto x = ck.number(r, l, f + ".when.reaches"))
        ev.reaches = *x;
    }
    if (e["lock"].IsDefined()) ev.lock = read_bodies(e["lock"], l, f + ".lock", model, ck);
    if (e["release"].IsDefined()) ev.release = read_bodies(e["release"], l, f + ".release", model, ck);
    if (!e["lock"].IsDefined() && !e["release"].IsDefined())
      ck.error(l, f, "no action; expected lock: [bodies] and/or release: [bodies]");
    for (int b : ev.lock)
      if (std::find(ev.release.begin(), ev.release.end(), b) != ev.release.end())
        ck.error(l, f, fmt::format("'{}' is both locked and released; expected one action per body",
                                   model.bodies[b].name));
    entry_ok.push_back(faults.size() == before);
    model.events.push_back(std::move(ev));
  }
  if (faults.size() > 0) return;

  // What can be known when the model is loaded: crossing events fire at
  // unknown times, so the joints they touch have an unknown state; the time
  // events change the others in (time, file) order.
  std::set<int> unknown;
  for (const Event& ev : model.events)
    if (ev.trigger == Event::Trigger::crossing) {
      unknown.insert(ev.lock.begin(), ev.lock.end());
      unknown.insert(ev.release.begin(), ev.release.end());
    }
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < model.events.size(); ++i)
    if (model.events[i].trigger == Event::Trigger::time) order.push_back(i);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return model.events[a].at < model.events[b].at; });
  LockSet state = initial_locks(model);
  std::map<int, std::string> why;  // body -> what set its state last
  for (std::size_t i = 0; i < model.bodies.size(); ++i)
    if (state[i]) why[static_cast<int>(i)] = "locked: true";
  for (std::size_t i : order) {
    const Event& ev = model.events[i];
    const std::string f = fmt::format("events[{}]", i);
    for (const bool locking : {true, false})
      for (int b : locking ? ev.lock : ev.release) {
        if (unknown.count(b)) continue;
        if ((state[b] != 0) == locking)
          ck.error(ev.line, f + (locking ? ".lock" : ".release"),
                   fmt::format("'{}' is already {} at t = {} ({}); expected a {} joint", model.bodies[b].name,
                               locking ? "locked" : "free", num(ev.at),
                               why.count(b) ? why[b] : "free from the start", locking ? "free" : "locked"));
        state[b] = locking ? 1 : 0;
        why[b] = fmt::format("{} by event '{}' at t = {}", locking ? "locked" : "released", ev.name, num(ev.at));
      }
  }
  // a crossing on the coordinate of a joint that is locked from the start and never released
  for (std::size_t i = 0; i < model.events.size(); ++i) {
    const Event& ev = model.events[i];
    if (ev.trigger != Event::Trigger::crossing || ev.coordinate < 0) continue;
    const int b = joint_body_of_coordinate(model, ev.coordinate);
    if (b < 0 || !model.bodies[b].joint.locked) continue;
    const bool released = std::any_of(model.events.begin(), model.events.end(), [&](const Event& o) {
      return std::find(o.release.begin(), o.release.end(), b) != o.release.end();
    });
    if (!released)
      ck.error(ev.line, fmt::format("events[{}].when.coordinate", i),
               fmt::format("'{}' belongs to the joint of '{}', which is locked from the start and no event releases "
                           "it; expected a coordinate of a joint that is free at some time",
                           model.q_names[ev.coordinate], model.bodies[b].name));
  }
}

}  // namespace kanegen
