#include "sim/event_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <ostream>

#include "engine/locks.hpp"

namespace kanegen {

namespace {
/// Time events within this of t are due at t (the segment ends exactly on them; this covers round-off).
double time_tol(double t) { return 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(t)); }
}  // namespace

EventRun::EventRun(const Model& model, double t0, const LockSet& initial_locks, const std::vector<Event>* events)
    : model_(model), events_(events ? *events : model.events), locks_(initial_locks), done_(events_.size(), 0) {
  if (locks_.size() != model.bodies.size()) locks_.assign(model.bodies.size(), 0);
  for (std::size_t i = 0; i < events_.size(); ++i) {
    const Event& e = events_[i];
    if (e.trigger == Event::Trigger::time) {
      by_time_.push_back(static_cast<int>(i));
      if (e.at < t0 - time_tol(t0)) done_[i] = 1;  // in the past
    } else {
      crossings_.push_back(static_cast<int>(i));
    }
  }
  std::stable_sort(by_time_.begin(), by_time_.end(), [&](int a, int b) { return events_[a].at < events_[b].at; });
  skip_done();
}

void EventRun::skip_done() {
  while (next_time_ < by_time_.size() && done_[by_time_[next_time_]]) ++next_time_;
}

double EventRun::next_stop(double t, double t_end) const {
  // the time events from next_time_ on are unfired, in time order; those at t itself are due (fired at t)
  for (std::size_t k = next_time_; k < by_time_.size(); ++k) {
    const double at = events_[by_time_[k]].at;
    if (at > t + time_tol(t)) return std::min(at, t_end);
  }
  return t_end;
}

std::vector<int> EventRun::time_events_due(double t) const {
  std::vector<int> due;
  for (std::size_t k = next_time_; k < by_time_.size(); ++k) {
    const int i = by_time_[k];
    if (events_[i].at > t + time_tol(t)) break;
    if (!done_[i] && std::abs(events_[i].at - t) <= time_tol(t)) due.push_back(i);
  }
  return due;
}

bool EventRun::time_event_due(double t) const { return !time_events_due(t).empty(); }

void EventRun::arm(OdeProblem& p) {
  armed_.clear();
  for (const int i : crossings_) {
    const Event& e = events_[i];
    if (done_[i]) continue;
    const int b = joint_body_of_coordinate(model_, e.coordinate);
    if (b >= 0 && locks_[b]) continue;  // fires only while its joint is free
    armed_.push_back(i);
  }
  p.n_events = static_cast<int>(armed_.size());
  if (armed_.empty()) {
    p.events = nullptr;
    return;
  }
  std::vector<std::pair<int, double>> g;  // (q index, value)
  for (int i : armed_) g.emplace_back(events_[i].coordinate, events_[i].reaches);
  p.events = [g](double, const double* x, double* out) {
    for (std::size_t k = 0; k < g.size(); ++k) out[k] = x[g[k].first] - g[k].second;
  };
}

int EventRun::fire(Engine& engine, double t, VecX& x, int crossing) {
  std::vector<int> due = time_events_due(t);
  if (crossing >= 0 && crossing < static_cast<int>(armed_.size())) due.push_back(armed_[crossing]);
  std::sort(due.begin(), due.end());
  due.erase(std::unique(due.begin(), due.end()), due.end());
  const int nq = model_.nq, nu = model_.nu;
  for (int i : due) {
    const Event& e = events_[i];
    done_[i] = 1;
    FiredEvent f;
    f.t = t;
    f.name = e.name;
    f.u_before = x.tail(nu);
    std::vector<std::string> acted, notes;
    bool locked_any = false, released_any = false;
    for (int b : e.lock) {
      if (locks_[b]) {
        notes.push_back(fmt::format("{} already locked: ignored", model_.bodies[b].name));
        continue;
      }
      locks_[b] = 1;
      locked_any = true;
      acted.push_back(model_.bodies[b].name);
    }
    for (int b : e.release) {
      if (!locks_[b]) {
        notes.push_back(fmt::format("{} already free: ignored", model_.bodies[b].name));
        continue;
      }
      locks_[b] = 0;
      released_any = true;
      acted.push_back(model_.bodies[b].name);
    }
    if (locked_any) {  // the plastic latch (dynamics.md, Locks)
      MatX M;
      const VecX q = x.head(nq);
      engine.mass_matrix(t, q, M);
      const LatchImpact impact = latch_impact(M, x.tail(nu), locked_speeds(model_, locks_));
      x.tail(nu) = impact.u_plus;
      f.energy_lost = impact.energy_lost;
    }
    engine.set_locks(locks_);
    f.u_after = x.tail(nu);
    f.action = locked_any && released_any ? "lock+release" : locked_any ? "lock" : released_any ? "release" : "none";
    for (const auto& a : acted) f.bodies += (f.bodies.empty() ? "" : " ") + a;
    for (const auto& n : notes) f.note += (f.note.empty() ? "" : "; ") + n;
    fired_.push_back(std::move(f));
  }
  skip_done();
  return static_cast<int>(due.size());
}

std::string events_summary(const std::vector<FiredEvent>& fired) {
  std::string s;
  for (const FiredEvent& f : fired) {
    s += s.empty() ? "" : "; ";
    s += fmt::format("{} at t = {:.10g}: {} {}", f.name, f.t, f.action, f.bodies);
    if (f.action.find("lock") == 0) s += fmt::format(" (energy lost {:.6g} J)", f.energy_lost);
    if (!f.note.empty()) s += fmt::format(" [{}]", f.note);
  }
  return s;
}

void write_events_csv(const std::vector<FiredEvent>& fired, std::ostream& out) {
  out << "t,name,action,bodies,energy_lost\n";
  for (const FiredEvent& f : fired)
    out << fmt::format("{:.17g},{},{},{},{:.17g}\n", f.t, f.name, f.action, f.bodies, f.energy_lost);
}

}  // namespace kanegen
