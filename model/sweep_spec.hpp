// SWEEP.yaml (docs/sweeps.md): a Monte Carlo sweep over one model: the
// dispersions of its runtime parameters and initial state, the number of
// runs, the integration, and the metrics recorded per run.
#pragma once

#include <string>
#include <vector>

#include "model/model.hpp"

namespace kanegen {

struct Dispersion {
  enum class Kind { normal, truncated_normal, uniform, choice };
  std::string target;          ///< a runtime parameter name (bus.mass, ant1.damping, ...) or q.<name> / u.<name>
  int line = 0;
  Kind kind = Kind::normal;
  double mean = 0.0;           ///< normal, truncated normal: the deviation's mean
  double sigma = 0.0;          ///< normal, truncated normal
  double low = 0.0, high = 0.0;  ///< uniform; truncated normal: the truncation interval (of the deviation)
  std::vector<double> values;  ///< choice
  bool relative = false;       ///< the draw scales the nominal value (x (1 + d)); else it is added (x + d)
};

struct Metric {
  enum class Stat { final, min, max, absmax, first_time };
  std::string name;
  std::string column;          ///< a column of the run's CSV (kanegen simulate)
  Stat stat = Stat::final;
  int line = 0;
  double threshold = 0.0;      ///< first_time: the first output time the column is above / below it
  bool above = true;
};

struct SweepSpec {
  std::string path;            ///< the sweep file
  std::string model_path;      ///< resolved relative to the sweep file
  long runs = 0;
  unsigned long long seed = 1;
  double t_end = 10.0, dt_out = 0.1;
  std::string integrator = "auto";
  double rtol = 1e-8, atol = 1e-10;
  std::string engine = "generated";
  std::vector<Dispersion> dispersions;
  std::vector<Metric> metrics;
  std::vector<std::string> envelopes;  ///< columns whose percentile envelopes are recorded
  std::string text;            ///< the file's bytes (its hash identifies a sweep's results)
};

/// Reads SWEEP.yaml; throws InputError naming file, line and field.
SweepSpec load_sweep_spec(const std::string& path);

const char* to_string(Metric::Stat s);
const char* to_string(Dispersion::Kind k);

}  // namespace kanegen
