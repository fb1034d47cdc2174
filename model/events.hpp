// Locks and events (model-format.md "Locks and events", dynamics.md "Locks"):
// which joints can lock, which speeds a lock set holds at zero, and the
// events of a model (time and coordinate-crossing triggers that lock and
// release joints during a run). The motion a lock defines (reduced equations,
// the plastic latch) lives in engine/locks.hpp; when events fire, in
// sim/event_runner.hpp.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

namespace YAML {
class Node;
}

namespace kanegen {

struct Model;
struct Joint;
struct Diagnostic;

struct Event {
  enum class Trigger { time, crossing };
  std::string name;
  int line = 0;                  ///< line of its entry in the model file (0: built in code)
  Trigger trigger = Trigger::time;
  double at = 0.0;               ///< time trigger [s]
  int coordinate = -1;           ///< crossing trigger: index in q
  double reaches = 0.0;          ///< crossing trigger: the value whose crossing fires it
  std::vector<int> lock;         ///< bodies whose joints it locks
  std::vector<int> release;      ///< bodies whose joints it releases
};

/// Whether a joint can be locked: it has degrees of freedom and is not prescribed.
bool joint_can_lock(const Joint& j);

/// Per body (model.bodies order): locked (1) or free (0); the model's
/// `locked: true` joints at the start of a run.
using LockSet = std::vector<char>;
LockSet initial_locks(const Model& model);
bool any_locked(const LockSet& locks);

/// The speeds a lock set holds at zero (indices into u, ascending).
std::vector<int> locked_speeds(const Model& model, const LockSet& locks);

/// The body whose joint coordinate q[k] is (-1 for a modal coordinate).
int joint_body_of_coordinate(const Model& model, int k);
/// The body whose joint speed u[k] is (-1 for a modal speed).
int joint_body_of_speed(const Model& model, int k);

/// Reads the `events:` list of a model file into model.events (the bodies are
/// known by then), checking what can be known when the model is loaded
/// (model-format.md): unknown bodies and coordinates, prescribed or fixed
/// joints, a crossing on a joint that is never free, non-finite values,
/// locking a joint that is locked (or releasing one that is free) at that
/// time. Appends one diagnostic per fault.
void read_events(const YAML::Node& events, const std::string& path, Model& model, std::vector<Diagnostic>& faults);

}  // namespace kanegen
