#include "sim/sweep.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <thread>

#include "model/diagnostics.hpp"
#include "model/model_hash.hpp"
#include "engine/initial_orbit.hpp"
#include "model/model_files.hpp"
#include "engine/load_model.hpp"
#include "model/output_file.hpp"
#include "model/parameters.hpp"
#include "model/state_io.hpp"
#include "sim/row_sink.hpp"
#include "sim/simulate.hpp"

namespace kanegen {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

std::string g17(double x) { return std::isnan(x) ? "nan" : fmt::format("{:.17g}", x); }

std::vector<double> parse_numbers(const std::string& s) {
  std::vector<double> v;
  const char* p = s.c_str();
  while (*p) {
    char* end = nullptr;
    const double x = std::strtod(p, &end);
    if (end == p) break;
    v.push_back(x);
    p = end;
    while (*p == ' ') ++p;
  }
  return v;
}

std::string join_numbers(const std::vector<double>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? " " : "") + g17(v[i]);
  return s;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::size_t a = 0;
  for (;;) {
    const std::size_t b = s.find(sep, a);
    out.push_back(s.substr(a, b == std::string::npos ? std::string::npos : b - a));
    if (b == std::string::npos) return out;
    a = b + 1;
  }
}

std::string csv_quoted(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string r = "\"";
  for (char c : s) r += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return r + "\"";
}

/// Percentile p (0..100) of sorted values, linear interpolation (numpy's default).
double percentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return kNaN;
  const double pos = p / 100.0 * static_cast<double>(sorted.size() - 1);
  const std::size_t i = static_cast<std::size_t>(std::floor(pos));
  const double f = pos - static_cast<double>(i);
  return i + 1 < sorted.size() ? sorted[i] * (1 - f) + sorted[i + 1] * f : sorted[i];
}

/// A run's metrics and envelopes, updated row by row as the run gives them.
class MetricSink final : public RowSink {
 public:
  MetricSink(const SweepPlan& plan, RunResult& r)
      : plan_(plan), r_(r), seen_(plan.spec.metrics.size(), false) {
    r_.envelopes.assign(plan.envelope_columns.size(), {});
  }
  void begin(const std::vector<std::string>&) override {}
  void row(const double* row, std::size_t) override {
    const auto& ms = plan_.spec.metrics;
    for (std::size_t k = 0; k < ms.size(); ++k) {
      if (plan_.metric_columns[k] < 0) continue;  // an event's (after the run)
      const double v = row[plan_.metric_columns[k]];
      double& m = r_.metrics[k];
      switch (ms[k].stat) {
        case Metric::Stat::final: m = v; break;
        case Metric::Stat::min: m = seen_[k] ? std::min(m, v) : v; break;
        case Metric::Stat::max: m = seen_[k] ? std::max(m, v) : v; break;
        case Metric::Stat::absmax: m = seen_[k] ? std::max(m, std::abs(v)) : std::abs(v); break;
        case Metric::Stat::first_time:
          if (std::isnan(m) && (ms[k].above ? v > ms[k].threshold : v < ms[k].threshold)) m = row[0];
          break;
      }
      seen_[k] = true;
    }
    for (std::size_t k = 0; k < plan_.envelope_columns.size(); ++k)
      r_.envelopes[k].push_back(row[plan_.envelope_columns[k]]);
  }

 private:
  const SweepPlan& plan_;
  RunResult& r_;
  std::vector<bool> seen_;
};

}  // namespace

SweepPlan plan_sweep(const SweepSpec& spec) {
  SweepPlan plan;
  plan.spec = spec;
  plan.model = load_model(spec.model_path);
  std::vector<Diagnostic> bad;
  auto fault = [&](int line, const std::string& field, const std::string& msg) {
    bad.push_back(Diagnostic{spec.path, line, field, msg});
  };
  // what one name sets: one value, or (a parameter group) several
  auto resolve = [&](const std::string& target, int line, const std::string& f) {
    std::vector<SweepPlan::Target> out;
    SweepPlan::Target t;
    const bool q = target.rfind("q.", 0) == 0, u = target.rfind("u.", 0) == 0, w = target.rfind("inputs.", 0) == 0;
    if (q || u || w) {
      const std::string name = target.substr(w ? 7 : 2);
      const int k = q ? plan.model.q_index(name) : u ? plan.model.speed_index(name) : plan.model.input_index(name);
      if (k < 0) {
        fault(line, f, fmt::format("'{}': the model has no {} named '{}'", target, q ? "coordinate" : u ? "speed" : "input", name));
        return out;
      }
      if (const auto& o = plan.model.initial_orbit; o && (q || u)) {  // as initial: refuses it
        const OrbitSetNames set = orbit_set_names(plan.model.bodies[plan.model.orbit_root].name, o->lvlh);
        const auto& names = q ? set.q : set.u;
        const std::string canonical = q ? name : plan.model.u_names[k];
        if (std::find(names.begin(), names.end(), canonical) != names.end()) {
          fault(line, f, fmt::format("'{}' is set by the model's initial.orbit{}; expected orbit.<element>{}", target,
                                     o->lvlh ? " with attitude: lvlh" : "",
                                     o->lvlh ? ", orbit.attitude_offset.x|y|z or orbit.rate_offset.x|y|z" : ""));
          return out;
        }
      }
      t.kind = q ? SweepPlan::Target::Kind::q : u ? SweepPlan::Target::Kind::u : SweepPlan::Target::Kind::input;
      t.index = k;
      t.nominal = q ? plan.model.q0(k) : u ? plan.model.u0(k) : 0.0;
      out.push_back(t);
    } else if (target.rfind("orbit.", 0) == 0) {
      static const std::vector<std::string> keys = {
          "a", "e", "i", "raan", "argp", "nu", "attitude_offset.x", "attitude_offset.y", "attitude_offset.z",
          "rate_offset.x", "rate_offset.y", "rate_offset.z"};
      const auto& o = plan.model.initial_orbit;
      const auto it = std::find(keys.begin(), keys.end(), target.substr(6));
      const int k = it == keys.end() ? -1 : static_cast<int>(it - keys.begin());
      if (!o || k < 0 || (k >= 6 && !o->lvlh)) {
        fault(line, f, fmt::format("'{}': {}", target,
                                   !o ? "the model has no initial.orbit"
                                   : k < 0 ? "expected orbit.a, .e, .i, .raan, .argp, .nu, .attitude_offset.x|y|z "
                                             "or .rate_offset.x|y|z"
                                           : "the offsets from the orbit frame need the model's attitude: lvlh"));
        return out;
      }
      const OrbitElements& el = o->elements;
      const double nominal[] = {el.a, el.e, el.i, el.raan, el.argp, el.nu, 0, 0, 0,
                                o->rate_offset_B(0), o->rate_offset_B(1), o->rate_offset_B(2)};
      t.kind = SweepPlan::Target::Kind::orbit;
      t.index = k;
      t.nominal = nominal[k];
      out.push_back(t);
    } else if (target.rfind("events.", 0) == 0) {
      const auto dot = target.rfind('.');
      const std::string name = target.substr(7, dot == std::string::npos || dot < 7 ? std::string::npos : dot - 7);
      const std::string what = dot == std::string::npos || dot < 7 ? "" : target.substr(dot + 1);
      int e = -1;
      for (std::size_t k = 0; k < plan.model.events.size(); ++k)
        if (plan.model.events[k].name == name) e = static_cast<int>(k);
      const Event* ev = e >= 0 ? &plan.model.events[e] : nullptr;
      const bool at = what == "at", reaches = what == "reaches";
      if (!ev || !(at || reaches) || (at && ev->trigger != Event::Trigger::time) ||
          (reaches && ev->trigger != Event::Trigger::crossing)) {
        fault(line, f, fmt::format("'{}': expected events.<name>.at (a time event) or events.<name>.reaches (a "
                                   "crossing event) of an event of the model{}",
                                   target, ev ? "" : fmt::format(" (it has no event '{}')", name)));
        return out;
      }
      t.kind = at ? SweepPlan::Target::Kind::event_at : SweepPlan::Target::Kind::event_reaches;
      t.index = e;
      t.nominal = at ? ev->at : ev->reaches;
      out.push_back(t);
    } else {
      std::vector<RuntimeParameter> ps;
      try {
        ps = expand_parameter(plan.model, target);
      } catch (const std::invalid_argument& e) {
        fault(line, f, e.what());
        return out;
      }
      for (const RuntimeParameter& rp : ps) {  // a name for several values (array.damping_ratio): one draw for all
        t.index = ensure_parameter(plan.model, rp);  // the sweep makes it a runtime parameter if it is not
        t.nominal = rp.nominal;
        out.push_back(t);
      }
    }
    return out;
  };
  std::vector<std::string> set_by;  // per member: the dispersion that sets it ("kind index")
  for (std::size_t i = 0; i < spec.dispersions.size(); ++i) {
    const Dispersion& d = spec.dispersions[i];
    std::vector<SweepPlan::Target> group;
    for (std::size_t m = 0; m < d.members.size(); ++m) {
      const std::string f = d.members.size() > 1 ? fmt::format("dispersions[{}].parameter[{}]", i, m)
                                                 : fmt::format("dispersions[{}].parameter", i);
      for (const SweepPlan::Target& t : resolve(d.members[m], d.line, f)) {
        const std::string key = fmt::format("{} {}", static_cast<int>(t.kind), t.index);
        if (std::find(set_by.begin(), set_by.end(), key) != set_by.end())
          fault(d.line, f, fmt::format("'{}' is dispersed twice (by this and an earlier dispersion)", d.members[m]));
        set_by.push_back(key);
        if (d.relative && t.nominal == 0.0)
          fault(d.line, f, fmt::format("relative: true on '{}', whose nominal value is 0: every run would get 0; "
                                       "expected relative: false (deviations added to the nominal value)",
                                       d.members[m]));
        group.push_back(t);
      }
    }
    plan.targets.push_back(group);
    if (d.kind == Dispersion::Kind::normal) plan.normal_dispersions.push_back(static_cast<int>(i));
  }
  // correlated normal draws: z = L n, L the Cholesky factor of the correlation matrix
  const Eigen::Index nn = static_cast<Eigen::Index>(plan.normal_dispersions.size());
  MatX C = MatX::Identity(nn, nn);
  auto normal_slot = [&](const std::string& name) {
    for (Eigen::Index k = 0; k < nn; ++k)
      if (spec.dispersions[plan.normal_dispersions[k]].target == name) return k;
    return Eigen::Index(-1);
  };
  for (const Correlation& c : spec.correlations) {
    const Eigen::Index a = normal_slot(c.a), b = normal_slot(c.b);
    if (a >= 0 && b >= 0) C(a, b) = C(b, a) = c.rho;
  }
  Eigen::LLT<MatX> llt(C);
  if (llt.info() != Eigen::Success || (nn > 0 && llt.matrixL().toDenseMatrix().diagonal().minCoeff() < 1e-12))
    fault(spec.correlations.empty() ? 1 : spec.correlations[0].line, "correlations",
          "the coefficients do not form a positive definite correlation matrix (no joint distribution has them)");
  else
    plan.correlation_factor = llt.matrixL();
  plan.columns = csv_columns(plan.model);
  auto column = [&](const std::string& c, int line, const std::string& field) {
    // q.<name> / u.<name>: a coordinate or a speed (also by a speed's older name)
    const Model& m = plan.model;
    if (c.rfind("event.", 0) == 0)
      for (std::size_t e = 0; e < m.events.size(); ++e) {
        if (c == "event." + m.events[e].name + ".t") return -static_cast<int>(2 * e + 2);
        if (c == "event." + m.events[e].name + ".energy_lost") return -static_cast<int>(2 * e + 3);
      }
    if (c.rfind("q.", 0) == 0 && m.q_index(c.substr(2)) >= 0) return 1 + m.q_index(c.substr(2));
    if (c.rfind("u.", 0) == 0 && m.speed_index(c.substr(2)) >= 0)
      return 1 + m.nq + static_cast<int>(m.prescribed_names.size()) + m.speed_index(c.substr(2));
    const auto it = std::find(plan.columns.begin(), plan.columns.end(), c);
    if (it == plan.columns.end()) {
      fault(line, field, fmt::format("no column '{}' in the runs' output; expected one of: {}", c, fmt::join(plan.columns, ", ")));
      return -1;
    }
    return static_cast<int>(it - plan.columns.begin());
  };
  for (std::size_t i = 0; i < spec.metrics.size(); ++i)
    plan.metric_columns.push_back(column(spec.metrics[i].column, spec.metrics[i].line, fmt::format("metrics[{}].column", i)));
  for (std::size_t i = 0; i < spec.envelopes.size(); ++i)
  {
    plan.envelope_columns.push_back(column(spec.envelopes[i], 1, fmt::format("envelopes[{}]", i)));
    if (plan.envelope_columns.back() < -1)
      fault(1, fmt::format("envelopes[{}]", i),
            fmt::format("'{}' is an event's value, one per run; expected a column of the runs' output",
                        spec.envelopes[i]));
  }
  try {
    (void)integrator_from_string(spec.integrator);
  } catch (const std::invalid_argument& e) {
    fault(1, "integrator", e.what());
  }
  if (!bad.empty()) throw InputError(bad);
  return plan;
}

std::string sweep_identity(const SweepPlan& plan) {
  return fnv1a64_hex(plan.spec.text + model_hash(plan.model)).substr(0, 8);
}

namespace {

/// Per dispersion its draw: the deviation d (x (1 + d) relative, x + d absolute) or a choice's value v
/// (x v relative, v absolute).
std::vector<double> deviations(const SweepPlan& plan, long index) {
  std::mt19937_64 rng(splitmix64(plan.spec.seed ^ splitmix64(static_cast<std::uint64_t>(index))));
  const auto& ds = plan.spec.dispersions;
  std::vector<double> dev(ds.size(), 0.0);
  VecX n(static_cast<Eigen::Index>(plan.normal_dispersions.size()));
  for (std::size_t i = 0, k = 0; i < ds.size(); ++i) {
    const Dispersion& d = ds[i];
    switch (d.kind) {
      case Dispersion::Kind::normal: n(static_cast<Eigen::Index>(k++)) = std::normal_distribution<double>(0.0, 1.0)(rng); break;
      case Dispersion::Kind::truncated_normal: {
        std::normal_distribution<double> N(d.mean, d.sigma);
        int tries = 0;
        do dev[i] = N(rng);
        while ((dev[i] < d.low || dev[i] > d.high) && ++tries < 10000);
        dev[i] = std::clamp(dev[i], d.low, d.high);
        break;
      }
      case Dispersion::Kind::uniform: dev[i] = std::uniform_real_distribution<double>(d.low, d.high)(rng); break;
      case Dispersion::Kind::choice:
        dev[i] = d.values[std::uniform_int_distribution<std::size_t>(0, d.values.size() - 1)(rng)];
        break;
    }
  }
  if (n.size() > 0) {
    const VecX z = plan.correlation_factor.triangularView<Eigen::Lower>() * n;
    for (Eigen::Index k = 0; k < z.size(); ++k) {
      const Dispersion& d = ds[plan.normal_dispersions[k]];
      dev[plan.normal_dispersions[k]] = d.mean + d.sigma * z(k);
    }
  }
  return dev;
}

double member_value(const Dispersion& d, const SweepPlan::Target& t, double dev) {
  if (d.kind == Dispersion::Kind::choice) return d.relative ? t.nominal * dev : dev;
  return d.relative ? t.nominal * (1.0 + dev) : t.nominal + dev;
}

/// Per dispersion the value of its first member (the table's column).
std::vector<double> first_member_values(const SweepPlan& plan, const std::vector<double>& dev) {
  std::vector<double> out;
  for (std::size_t i = 0; i < dev.size(); ++i)
    out.push_back(plan.targets[i].empty() ? dev[i] : member_value(plan.spec.dispersions[i], plan.targets[i][0], dev[i]));
  return out;
}

}  // namespace

std::vector<double> draw(const SweepPlan& plan, long index) { return first_member_values(plan, deviations(plan, index)); }

RunSetup run_setup(const SweepPlan& plan, long index) {
  const Model& model = plan.model;
  RunSetup r;
  r.parameters = Engine::nominal_parameters(model);
  r.state = initial_state(model);
  r.events = model.events;
  const std::vector<double> dev = deviations(plan, index);
  r.values = first_member_values(plan, dev);
  std::optional<InitialOrbit> orbit = model.initial_orbit;
  Vec3 turn = Vec3::Zero();  // orbit.attitude_offset.x|y|z
  for (std::size_t i = 0; i < plan.targets.size(); ++i)
    for (const SweepPlan::Target& t : plan.targets[i]) {
      const double v = member_value(plan.spec.dispersions[i], t, dev[i]);
      switch (t.kind) {
        case SweepPlan::Target::Kind::parameter: r.parameters(t.index) = v; break;
        case SweepPlan::Target::Kind::q: r.state.q(t.index) = v; break;
        case SweepPlan::Target::Kind::u: r.state.u(t.index) = v; break;
        case SweepPlan::Target::Kind::input: r.state.w(t.index) = v; break;
        case SweepPlan::Target::Kind::event_at: r.events[t.index].at = v; break;
        case SweepPlan::Target::Kind::event_reaches: r.events[t.index].reaches = v; break;
        case SweepPlan::Target::Kind::orbit: {
          OrbitElements& el = orbit->elements;
          double* element[] = {&el.a, &el.e, &el.i, &el.raan, &el.argp, &el.nu};
          if (t.index < 6) *element[t.index] = v;
          else if (t.index < 9) turn(t.index - 6) = v;
          else orbit->rate_offset_B(t.index - 9) = v;
          break;
        }
      }
    }
  for (const auto& slot : model.quaternions) r.state.q.segment<4>(slot.q).normalize();
  if (orbit) {  // each run's centre of mass on its orbit: with its own masses, configuration and elements
    if (turn.norm() > 0) orbit->R_LB = orbit->R_LB * Eigen::AngleAxisd(turn.norm(), turn.normalized()).toRotationMatrix();
    try {
      Model m = model;
      apply_parameters(m, m.parameters, r.parameters);
      m.q0 = r.state.q;
      m.u0 = r.state.u;
      place_on_orbit(m, model.orbit_root, *orbit);
      r.state.q = m.q0;
      r.state.u = m.u0;
    } catch (const std::exception& e) {
      r.failure = std::string("the run's orbit: ") + e.what();
    }
  }
  SimulationOptions& o = r.options;
  o.t_end = plan.spec.t_end;
  o.dt_out = plan.spec.dt_out;
  o.integrator.kind = integrator_from_string(plan.spec.integrator);
  o.integrator.rtol = plan.spec.rtol;
  o.integrator.atol = plan.spec.atol;
  o.wall_time_limit = plan.spec.run_time_limit;
  if (!model.events.empty()) o.events = r.events;
  return r;
}

RunResult run_one(Engine& engine, const SweepPlan& plan, long index, std::ostream* csv,
                  const ControllerFactory& controller) {
  const auto t0 = std::chrono::steady_clock::now();
  const Model& model = plan.model;
  RunResult r;
  r.index = index;
  RunSetup setup = run_setup(plan, index);
  r.values = setup.values;
  r.metrics.assign(plan.spec.metrics.size(), kNaN);
  const State& s = setup.state;
  const VecX& p = setup.parameters;
  SimulationOptions& o = setup.options;
  MetricSink metrics(plan, r);
  std::unique_ptr<CsvRowWriter> text;  // with `csv`: the rows to it as well
  std::unique_ptr<TeeRowSink> both;
  if (csv) {
    text = std::make_unique<CsvRowWriter>(*csv);
    both = std::make_unique<TeeRowSink>(metrics, *text);
  }
  std::vector<FiredEvent> fired;
  try {
    if (!setup.failure.empty()) throw std::runtime_error(setup.failure);
    engine.set_parameters(p);
    if (controller) o.controller = controller(model, index);
    const SimulationResult sr = simulate(engine, s, o, both ? static_cast<RowSink&>(*both) : metrics);
    r.integration_s = sr.stats.wall_seconds;
    fired = sr.events;
  } catch (const std::exception& e) {
    std::string why = e.what();
    why = why.substr(0, why.find('\n'));
    if (why.size() > 300) why = why.substr(0, 300) + "...";
    r.status = "failed: " + why;
    r.envelopes.clear();
    std::fill(r.metrics.begin(), r.metrics.end(), kNaN);
  }
  if (r.ok()) {
    const auto& ms = plan.spec.metrics;
    for (std::size_t k = 0; k < ms.size(); ++k) {  // an event's time or energy lost, NaN if it did not fire
      const int c = plan.metric_columns[k];
      if (c >= 0) continue;
      const std::size_t e = static_cast<std::size_t>(-c - 2) / 2;
      for (const FiredEvent& f : fired)
        if (f.name == model.events[e].name) r.metrics[k] = (-c - 2) % 2 == 0 ? f.t : f.energy_lost;
    }
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

std::string serialize(const RunResult& r) {
  std::string status = r.status;
  std::replace(status.begin(), status.end(), '\t', ' ');
  std::replace(status.begin(), status.end(), '\n', ' ');
  std::string s = fmt::format("{}\t{}\t{}\t{}\t{}\t{}\t", r.index, status, join_numbers(r.values), join_numbers(r.metrics),
                              g17(r.wall_s), g17(r.integration_s));
  for (std::size_t k = 0; k < r.envelopes.size(); ++k) s += (k ? "|" : "") + join_numbers(r.envelopes[k]);
  return s + "\tend";  // a line cut short (an interrupted write) lacks it
}

RunResult deserialize(const std::string& line) {
  const auto f = split(line, '\t');
  if (f.size() != 8 || f[7] != "end") throw std::runtime_error("malformed or incomplete sweep result line");
  RunResult r;
  r.index = std::stol(f[0]);
  r.status = f[1];
  r.values = parse_numbers(f[2]);
  r.metrics = parse_numbers(f[3]);
  r.wall_s = std::strtod(f[4].c_str(), nullptr);
  r.integration_s = std::strtod(f[5].c_str(), nullptr);
  if (!f[6].empty())
    for (const auto& e : split(f[6], '|')) r.envelopes.push_back(parse_numbers(e));
  return r;
}

void run_on_threads(const SweepPlan& plan, const std::vector<long>& indices, int threads,
                    const std::function<std::unique_ptr<Engine>(const Model&)>& make_engine,
                    const std::function<void(RunResult&&)>& done, const ControllerFactory& controller) {
  threads = std::max(1, std::min<int>(threads, static_cast<int>(indices.size())));
  // engines made here, one after the other (the JIT compiles and caches once)
  std::vector<std::unique_ptr<Engine>> engines;
  for (int k = 0; k < threads; ++k) engines.push_back(make_engine(plan.model));
  std::atomic<std::size_t> next{0};
  std::mutex m;
  std::exception_ptr error;
  auto work = [&](Engine* e) {
    try {
      for (std::size_t i; (i = next++) < indices.size();) {
        RunResult r = run_one(*e, plan, indices[i], nullptr, controller);
        std::lock_guard<std::mutex> lock(m);
        done(std::move(r));
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(m);
      if (!error) error = std::current_exception();
      next = indices.size();
    }
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(work, engines[k].get());
  work(engines[0].get());
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

std::vector<std::string> sweep_input_files(const SweepPlan& plan) {
  std::vector<std::string> files{plan.spec.path};
  for (const std::string& f : model_files(plan.model)) files.push_back(f);
  return files;
}

void check_sweep_output_directory(const std::string& option, const std::string& dir,
                                  const std::vector<std::string>& merged) {
  check_output_directory_option(option, dir);
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path out = fs::weakly_canonical(fs::absolute(dir), ec);
  for (const std::string& m : merged)
    if (fs::weakly_canonical(fs::absolute(m), ec) == out)
      throw InputError(Diagnostic{option, 0, "",
                                  fmt::format("cannot write '{}': it is a shard directory merged by this command; "
                                              "expected another directory",
                                              dir)});
}

void write_sweep_outputs(const SweepPlan& plan, const std::vector<RunResult>& results, const std::string& dir) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  const auto& spec = plan.spec;
  // ---- runs.csv
  std::string t = "run,status";
  for (const auto& d : spec.dispersions) t += "," + d.target;
  for (const auto& m : spec.metrics) t += "," + m.name;
  t += "\n";
  std::string timing = "run,wall_s,integration_s\n";
  for (const RunResult& r : results) {
    t += fmt::format("{},{}", r.index, csv_quoted(r.status));
    for (double v : r.values) t += "," + g17(v);
    for (double v : r.metrics) t += "," + g17(v);
    t += "\n";
    timing += fmt::format("{},{:.6f},{:.6f}\n", r.index, r.wall_s, r.integration_s);
  }
  write_file_atomically((fs::path(dir) / "runs.csv").string(), t);
  write_file_atomically((fs::path(dir) / "timing.csv").string(), timing);

  // ---- summary: every dispersed value and metric over the successful runs
  long failed = 0;
  nlohmann::ordered_json failures = nlohmann::ordered_json::array();
  for (const RunResult& r : results)
    if (!r.ok()) {
      ++failed;
      if (failures.size() < 20) failures.push_back({{"run", r.index}, {"status", r.status}});
    }
  nlohmann::ordered_json j;
  j["sweep"] = spec.path;
  j["identity"] = sweep_identity(plan);
  j["model"] = plan.model.name;
  j["runs"] = results.size();
  j["failed"] = failed;
  j["failures"] = failures;
  std::string md = fmt::format("# Sweep {} ({} runs, {} failed)\n\n| quantity | n | mean | std | min (run) | p5 | p50 | p95 | max (run) | not reached |\n|---|---|---|---|---|---|---|---|---|---|\n",
                               spec.path, results.size(), failed);
  auto stats = [&](const std::string& name, auto value_of) {
    std::vector<std::pair<double, long>> v;
    long missing = 0;
    for (const RunResult& r : results) {
      if (!r.ok()) continue;
      const double x = value_of(r);
      if (std::isnan(x)) ++missing;
      else v.push_back({x, r.index});
    }
    std::sort(v.begin(), v.end());
    std::vector<double> xs;
    double mean = 0, var = 0;
    for (const auto& [x, i] : v) xs.push_back(x), mean += x;
    if (!xs.empty()) mean /= static_cast<double>(xs.size());
    for (double x : xs) var += (x - mean) * (x - mean);
    const double sd = xs.size() > 1 ? std::sqrt(var / static_cast<double>(xs.size() - 1)) : 0.0;
    nlohmann::ordered_json s;
    s["n"] = xs.size();
    s["not_reached"] = missing;
    if (!xs.empty()) {
      s["mean"] = mean;
      s["std"] = sd;
      s["min"] = {{"value", v.front().first}, {"run", v.front().second}};
      s["p5"] = percentile(xs, 5);
      s["p50"] = percentile(xs, 50);
      s["p95"] = percentile(xs, 95);
      s["max"] = {{"value", v.back().first}, {"run", v.back().second}};
      auto worst = nlohmann::ordered_json::array();
      for (std::size_t k = 0; k < std::min<std::size_t>(5, v.size()); ++k)
        worst.push_back({{"run", v[v.size() - 1 - k].second}, {"value", v[v.size() - 1 - k].first}});
      s["largest"] = worst;
      md += fmt::format("| {} | {} | {:.6g} | {:.3g} | {:.6g} ({}) | {:.6g} | {:.6g} | {:.6g} | {:.6g} ({}) | {} |\n", name,
                        xs.size(), mean, sd, v.front().first, v.front().second, percentile(xs, 5), percentile(xs, 50),
                        percentile(xs, 95), v.back().first, v.back().second, missing);
    } else {
      md += fmt::format("| {} | 0 | | | | | | | | {} |\n", name, missing);
    }
    return s;
  };
  nlohmann::ordered_json jp, jm;
  for (std::size_t i = 0; i < spec.dispersions.size(); ++i)
    jp[spec.dispersions[i].target] = stats(spec.dispersions[i].target, [i](const RunResult& r) { return r.values[i]; });
  for (std::size_t i = 0; i < spec.metrics.size(); ++i)
    jm[spec.metrics[i].name] = stats(spec.metrics[i].name, [i](const RunResult& r) { return r.metrics[i]; });
  j["dispersions"] = jp;
  j["metrics"] = jm;
  if (failed) {
    md += "\nFailed runs (first 20):\n\n";
    for (const auto& f : failures) md += fmt::format("- run {}: {}\n", f["run"].get<long>(), f["status"].get<std::string>());
  }
  write_file_atomically((fs::path(dir) / "summary.json").string(), j.dump(1) + "\n");
  write_file_atomically((fs::path(dir) / "summary.md").string(), md);

  // ---- percentile envelopes over the successful runs
  for (std::size_t k = 0; k < plan.envelope_columns.size(); ++k) {
    std::size_t rows = 0;
    for (const RunResult& r : results)
      if (r.ok() && k < r.envelopes.size()) rows = std::max(rows, r.envelopes[k].size());
    std::string e = "t,min,p5,p50,p95,max\n";
    for (std::size_t i = 0; i < rows; ++i) {
      std::vector<double> xs;
      for (const RunResult& r : results)
        if (r.ok() && k < r.envelopes.size() && i < r.envelopes[k].size()) xs.push_back(r.envelopes[k][i]);
      std::sort(xs.begin(), xs.end());
      const double tt = std::min(spec.t_end, static_cast<double>(i) * spec.dt_out);
      e += fmt::format("{},{},{},{},{},{}\n", g17(tt), g17(xs.front()), g17(percentile(xs, 5)), g17(percentile(xs, 50)),
                       g17(percentile(xs, 95)), g17(xs.back()));
    }
    write_file_atomically((fs::path(dir) / ("envelope_" + spec.envelopes[k] + ".csv")).string(), e);
  }
}

}  // namespace kanegen
