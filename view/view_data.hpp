// What `kanegen view` draws (issue 37), computed by kanegen's own kinematics
// (dynamics/kinematics.hpp, the generic engine's): per frame, every body's
// pose in N, every joint frame's pose in N and every flexible body's node
// positions in N (displaced, with foreshortening); once, every body's shape
// (the uniform box of its rigid part's mass and principal inertia), its joint
// (type, axes, locked) and its nodes' rest positions. The page only draws.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "model/model.hpp"
#include "view/run_table.hpp"

namespace kanegen {

struct ViewOptions {
  int frames = 500;                  ///< most frames kept from a run (evenly in time, plus both rows of each event)
  std::vector<std::string> columns;  ///< run columns plotted beside the view; empty: T, V and the root's rates
  /// The run's events table (kanegen simulate --events): the timeline's marks named, and each frame's locked
  /// joints (the model's `locked: true` ones, then each lock and release in time order).
  const std::vector<RunEvent>* events = nullptr;
};

/// The rows of a run kept as frames: all when there are at most `frames`, else the rows nearest to `frames`
/// evenly spaced times, and both rows of every event (two rows at one time), ascending.
std::vector<int> view_rows(const RunTable& run, int frames);

/// The page's data. `run` null: one frame, the model's initial state. Throws InputError naming the run's file
/// for a CSV of another model (a coordinate or speed column missing) or an unknown column in options.columns,
/// and the events file (`events_path`) for an event on a body the model does not have.
nlohmann::json view_data(const Model& model, const RunTable* run, const ViewOptions& options,
                         const std::string& events_path = "");

}  // namespace kanegen
