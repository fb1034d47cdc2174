// The events of a run (model-format.md "Locks and events"): which are due,
// which crossing functions the integrator watches in the current segment,
// and what firing one does: lock (a perfectly plastic latch: the speeds jump,
// kinetic energy is lost; engine/locks.hpp) or release (no speed changes).
// simulate() integrates segment by segment between the stops this gives.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "engine/engine.hpp"
#include "sim/integrators.hpp"

namespace kanegen {

/// One event that fired, as the events table (interface.md) reports it.
struct FiredEvent {
  double t = 0;
  std::string name;
  std::string action;       ///< "lock", "release" or "lock+release"
  std::string bodies;       ///< the bodies acted on, space-separated
  double energy_lost = 0;   ///< kinetic energy the latch took [J] (0 for a release)
  std::string note;         ///< e.g. "panel already locked: ignored"
  VecX u_before, u_after;   ///< the speeds just before and after
};

class EventRun {
 public:
  /// `initial_locks`: the locks at t0 (State::locked). Events due before t0
  /// do not fire. `events`: instead of the model's (e.g. a sweep's dispersed times and values).
  EventRun(const Model& model, double t0, const LockSet& initial_locks, const std::vector<Event>* events = nullptr);
  const LockSet& locks() const { return locks_; }
  /// The first unfired time event after t (exclusive) before t_end, else t_end.
  double next_stop(double t, double t_end) const;
  /// Whether an unfired time event is due at t.
  bool time_event_due(double t) const;
  /// Arms the integrator with the crossing events that can fire now (unfired,
  /// their coordinate's joint free): p.events, p.n_events.
  void arm(OdeProblem& p);
  /// Fires, in file order, the crossing event that stopped the segment
  /// (`crossing`: OdeProblem event function index, -1 if none) and the time
  /// events due at t, with the state x = [q; u] there (u jumps at a lock).
  /// Applies the new locks to the engine. Returns the number fired.
  int fire(Engine& engine, double t, VecX& x, int crossing);
  const std::vector<FiredEvent>& fired() const { return fired_; }

 private:
  const Model& model_;
  std::vector<Event> events_;
  LockSet locks_;
  std::vector<char> done_;          ///< per model event: fired (or in the past at the start)
  std::vector<int> armed_;          ///< event function i -> model event index
  std::vector<FiredEvent> fired_;
  /// The time events by time (file order among equal times) and the first
  /// of them not yet fired or passed: next_stop, time_event_due and fire look
  /// from there, so a run's cost is linear in its number of events.
  std::vector<int> by_time_;
  std::size_t next_time_ = 0;
  std::vector<int> crossings_;      ///< the crossing events, in file order
  /// Moves next_time_ past the time events fired or passed.
  void skip_done();
  /// The unfired time events due at t (model event indices).
  std::vector<int> time_events_due(double t) const;
};

/// "deploy at t = 10: release panel; latch at t = 12.3: lock panel (energy lost 0.53 J)"
std::string events_summary(const std::vector<FiredEvent>& fired);

/// The events table of `simulate --events FILE` (interface.md): t, name, action, bodies, energy_lost.
void write_events_csv(const std::vector<FiredEvent>& fired, std::ostream& out);

}  // namespace kanegen
