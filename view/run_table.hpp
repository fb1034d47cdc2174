// A run's CSV as `kanegen simulate` writes it (interface.md): a header of
// column names, then one row of numbers per output time (two rows at the time
// of an event: before and after it). Read whole, checked, for `kanegen view`.
#pragma once

#include <string>
#include <vector>

#include "model/model.hpp"
#include "model/state_io.hpp"

namespace kanegen {

struct RunTable {
  std::string path;
  std::vector<std::string> names;  ///< the header's column names
  MatX rows;                       ///< one row per line after the header
  /// Column index of `name`, or -1.
  int column(const std::string& name) const;
};

/// Reads a CSV written by `kanegen simulate`. Throws InputError naming the file, line and column for a missing
/// or empty file, a header with an empty or repeated name, a row of another length or with a value that is no
/// finite number, or times that decrease.
RunTable read_run_table(const std::string& path);

/// One row of the events table `kanegen simulate --events` writes (interface.md): t, name, action, bodies.
struct RunEvent {
  double t = 0;
  std::string name, action;
  std::vector<std::string> bodies;
};

/// Reads an events table. Throws InputError naming the file, line and column for a missing file, a header other
/// than t,name,action,bodies,energy_lost, or a row that cannot be read.
std::vector<RunEvent> read_events_table(const std::string& path);

/// The columns of `model`'s state in the run: the column of each coordinate (model.q_names) then of each speed
/// (u_names). Throws InputError (the run's file, line 1, field "header") naming the first name missing: a CSV
/// from another model.
std::vector<int> state_columns(const RunTable& run, const Model& model);

}  // namespace kanegen

namespace kanegen {

/// The state (t, q, u) of `model` at row `row` of the run, through the columns state_columns() gave.
State run_state(const RunTable& run, const Model& model, const std::vector<int>& columns, int row);

}  // namespace kanegen
