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
  /// The dispersion's name (its column in runs.csv): `name:`, else `parameter:` as written (a list joined by '+').
  std::string target;
  /// What one draw sets (`parameter:` a name or a list of names): runtime parameters (bus.mass;
  /// array.damping_ratio stands for every mode's), q.<name> / u.<name>, inputs.<name>,
  /// events.<name>.at / .reaches. Every member gets the same draw: x_i (1 + d) relative, x_i + d absolute.
  std::vector<std::string> members;
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

/// Correlated normal draws (`correlations:`): the standard normal deviates of two normal dispersions
/// with correlation coefficient rho (all pairs together must form a positive definite matrix).
struct Correlation {
  std::string a, b;  ///< the dispersions' names
  double rho = 0.0;
  int line = 0;
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
  std::vector<Correlation> correlations;
  /// Seconds of wall time a run may take (`run_time_limit:`; 0: no limit): a run past it is recorded failed.
  double run_time_limit = 0.0;
  std::vector<Metric> metrics;
  std::vector<std::string> envelopes;  ///< columns whose percentile envelopes are recorded
  std::string text;            ///< the file's bytes (its hash identifies a sweep's results)
};

/// Reads SWEEP.yaml; throws InputError naming file, line and field.
SweepSpec load_sweep_spec(const std::string& path);

const char* to_string(Metric::Stat s);
const char* to_string(Dispersion::Kind k);

}  // namespace kanegen
