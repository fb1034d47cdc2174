#include "model/sweep_spec.hpp"

#include <fmt/format.h>

#include <filesystem>

#include "model/yaml_check.hpp"

namespace kanegen {

using namespace yamlcheck;

const char* to_string(Metric::Stat s) {
  switch (s) {
    case Metric::Stat::final: return "final";
    case Metric::Stat::min: return "min";
    case Metric::Stat::max: return "max";
    case Metric::Stat::absmax: return "absmax";
    case Metric::Stat::first_time: return "first_time";
  }
  return "?";
}

const char* to_string(Dispersion::Kind k) {
  switch (k) {
    case Dispersion::Kind::normal: return "normal";
    case Dispersion::Kind::truncated_normal: return "truncated_normal";
    case Dispersion::Kind::uniform: return "uniform";
    case Dispersion::Kind::choice: return "choice";
  }
  return "?";
}

SweepSpec load_sweep_spec(const std::string& path) {
  std::vector<Diagnostic> diags;
  bool ok = false;
  const YAML::Node root = parse_file(path, kMaxModelFileBytes, diags, ok);
  if (!ok) throw InputError(diags);
  Checker ck(path, diags);
  SweepSpec s;
  s.path = path;
  if (auto text = read_input_text(path, kMaxModelFileBytes, diags)) s.text = *text;
  if (!ck.expect_map(root, 1, "(document)")) throw InputError(diags);
  ck.check_keys(root, "", {"model", "runs", "seed", "t_end", "dt_out", "integrator", "rtol", "atol", "engine",
                           "dispersions", "correlations", "run_time_limit", "metrics", "envelopes"});
  auto required = [&](const char* key) {
    if (!root[key].IsDefined()) ck.error(1, key, "missing");
    return root[key].IsDefined();
  };
  if (required("model"))
    if (auto m = ck.string(root["model"], 1, "model"))
      s.model_path = (std::filesystem::path(path).parent_path() / *m).lexically_normal().string();
  if (required("runs"))
    if (auto r = ck.integer(root["runs"], 1, "runs")) {
      if (*r < 1 || *r > 100'000'000)
        ck.error(root["runs"], 1, "runs", fmt::format("{}; expected 1 to 1e8 runs", *r));
      else
        s.runs = *r;
    }
  if (root["seed"].IsDefined())
    if (auto r = ck.integer(root["seed"], 1, "seed")) {
      if (*r < 0) ck.error(root["seed"], 1, "seed", "negative; expected an integer >= 0");
      else s.seed = static_cast<unsigned long long>(*r);
    }
  if (required("t_end"))
    if (auto v = ck.positive(root["t_end"], 1, "t_end", "a final time > 0")) s.t_end = *v;
  if (root["dt_out"].IsDefined())
    if (auto v = ck.positive(root["dt_out"], 1, "dt_out", "an output step > 0")) s.dt_out = *v;
  if (root["rtol"].IsDefined())
    if (auto v = ck.positive(root["rtol"], 1, "rtol", "a tolerance in (0, 1)")) s.rtol = *v;
  if (root["atol"].IsDefined())
    if (auto v = ck.positive(root["atol"], 1, "atol", "a tolerance > 0")) s.atol = *v;
  if (root["integrator"].IsDefined())
    if (auto v = ck.string(root["integrator"], 1, "integrator")) s.integrator = *v;
  if (root["engine"].IsDefined())
    if (auto v = ck.string(root["engine"], 1, "engine")) {
      if (*v != "generated" && *v != "generic") ck.error(root["engine"], 1, "engine", fmt::format("'{}'; expected generated or generic", *v));
      else s.engine = *v;
    }
  if (root["run_time_limit"].IsDefined())
    if (auto v = ck.positive(root["run_time_limit"], 1, "run_time_limit", "seconds of wall time per run > 0"))
      s.run_time_limit = *v;
  if (s.t_end > 0 && s.dt_out > 0 && s.t_end / s.dt_out > 1e6)
    ck.error(root["dt_out"].IsDefined() ? line_of(root["dt_out"]) : 1, "dt_out",
             fmt::format("{} output rows per run; expected at most 1e6", s.t_end / s.dt_out));

  const YAML::Node ds = root["dispersions"];
  if (ds.IsDefined() && ck.expect_seq(ds, 1, "dispersions"))
    for (std::size_t i = 0; i < ds.size(); ++i) {
      const std::string f = fmt::format("dispersions[{}]", i);
      const YAML::Node e = ds[i];
      if (!ck.expect_map(e, line_of(ds), f)) continue;
      const int l = line_of(e);
      ck.check_keys(e, f, {"name", "parameter", "distribution", "mean", "sigma", "low", "high", "values", "relative"});
      Dispersion d;
      d.line = l;
      const YAML::Node par = e["parameter"];
      if (!par.IsDefined()) {
        ck.error(l, f + ".parameter", "missing; expected a runtime parameter (bus.mass, ...), q.<name> / u.<name>, "
                                      "inputs.<name>, or a list of them (one draw for all)");
      } else if (par.IsSequence()) {
        for (std::size_t k = 0; k < par.size(); ++k)
          if (auto p = ck.string(par[k], l, fmt::format("{}.parameter[{}]", f, k))) d.members.push_back(*p);
        if (par.size() == 0) ck.error(par, l, f + ".parameter", "an empty list; expected at least one name");
        d.target = fmt::format("{}", fmt::join(d.members, "+"));
      } else if (auto p = ck.string(par, l, f + ".parameter")) {
        d.target = *p;
        d.members = {*p};
      }
      if (e["name"].IsDefined())
        if (auto n = ck.string(e["name"], l, f + ".name")) d.target = *n;
      std::string kind = "normal";
      if (e["distribution"].IsDefined())
        if (auto k = ck.string(e["distribution"], l, f + ".distribution")) kind = *k;
      const std::vector<std::string> kinds = {"normal", "truncated_normal", "uniform", "choice"};
      const auto it = std::find(kinds.begin(), kinds.end(), kind);
      if (it == kinds.end()) {
        ck.error(e["distribution"], l, f + ".distribution",
                 fmt::format("'{}'{}; expected normal, truncated_normal, uniform or choice", kind, did_you_mean(kind, kinds)));
        continue;
      }
      d.kind = static_cast<Dispersion::Kind>(it - kinds.begin());
      auto num = [&](const char* key, double& out, bool needed) {
        if (!e[key].IsDefined()) {
          if (needed) ck.error(l, f + "." + key, fmt::format("missing; a {} distribution needs it", kind));
          return;
        }
        if (auto v = ck.number(e[key], l, f + "." + key)) out = *v;
      };
      const bool normal = d.kind == Dispersion::Kind::normal || d.kind == Dispersion::Kind::truncated_normal;
      num("sigma", d.sigma, normal);
      num("mean", d.mean, false);
      num("low", d.low, d.kind == Dispersion::Kind::uniform || d.kind == Dispersion::Kind::truncated_normal);
      num("high", d.high, d.kind == Dispersion::Kind::uniform || d.kind == Dispersion::Kind::truncated_normal);
      if (normal && !(d.sigma >= 0)) ck.error(e["sigma"], l, f + ".sigma", "negative; expected sigma >= 0");
      if ((d.kind == Dispersion::Kind::uniform || d.kind == Dispersion::Kind::truncated_normal) && !(d.low < d.high))
        ck.error(e, l, f, fmt::format("low {} is not below high {}", d.low, d.high));
      if (d.kind == Dispersion::Kind::truncated_normal && !(d.low <= d.mean && d.high >= d.mean))
        ck.error(e, l, f, "the truncation interval [low, high] must contain the mean (default 0)");
      if (d.kind == Dispersion::Kind::choice) {
        if (!e["values"].IsDefined()) ck.error(l, f + ".values", "missing; a choice needs a list of values");
        else if (ck.expect_seq(e["values"], l, f + ".values")) {
          for (std::size_t k = 0; k < e["values"].size(); ++k)
            if (auto v = ck.number(e["values"][k], l, fmt::format("{}.values[{}]", f, k))) d.values.push_back(*v);
          if (d.values.empty()) ck.error(e["values"], l, f + ".values", "empty; expected at least one value");
        }
      }
      if (e["relative"].IsDefined())
        if (auto b = ck.boolean(e["relative"], l, f + ".relative")) d.relative = *b;
      for (const Dispersion& o : s.dispersions)
        if (o.target == d.target && !d.target.empty())
          ck.error(e, l, f, fmt::format("'{}' is dispersed twice (give one of them a name: or one list)", d.target));
      s.dispersions.push_back(d);
    }

  const YAML::Node cs = root["correlations"];
  if (cs.IsDefined() && ck.expect_seq(cs, 1, "correlations"))
    for (std::size_t i = 0; i < cs.size(); ++i) {
      const std::string f = fmt::format("correlations[{}]", i);
      const YAML::Node e = cs[i];
      if (!ck.expect_map(e, line_of(cs), f)) continue;
      const int l = line_of(e);
      ck.check_keys(e, f, {"between", "rho"});
      Correlation c;
      c.line = l;
      const YAML::Node bw = e["between"];
      if (!bw.IsDefined() || !bw.IsSequence() || bw.size() != 2) {
        ck.error(bw.IsDefined() ? bw : e, l, f + ".between", "expected the names of two normal dispersions: [a, b]");
        continue;
      }
      auto a = ck.string(bw[0], l, f + ".between[0]");
      auto b = ck.string(bw[1], l, f + ".between[1]");
      if (!a || !b) continue;
      c.a = *a, c.b = *b;
      if (!e["rho"].IsDefined()) ck.error(l, f + ".rho", "missing; expected a correlation coefficient in (-1, 1)");
      else if (auto r = ck.number(e["rho"], l, f + ".rho")) {
        if (!(*r > -1 && *r < 1)) ck.error(e["rho"], l, f + ".rho", fmt::format("{}; expected a coefficient in (-1, 1)", *r));
        c.rho = *r;
      }
      auto find = [&](const std::string& n) -> const Dispersion* {
        for (const Dispersion& d : s.dispersions)
          if (d.target == n) return &d;
        return nullptr;
      };
      for (const std::string* n : {&c.a, &c.b}) {
        const Dispersion* d = find(*n);
        if (!d) ck.error(bw, l, f + ".between", fmt::format("'{}' is not the name of a dispersion of this file", *n));
        else if (d->kind != Dispersion::Kind::normal)
          ck.error(bw, l, f + ".between", fmt::format("'{}' is a {} dispersion; only normal ones can be correlated", *n, to_string(d->kind)));
      }
      if (c.a == c.b) ck.error(bw, l, f + ".between", fmt::format("'{}' with itself", c.a));
      for (const Correlation& o : s.correlations)
        if ((o.a == c.a && o.b == c.b) || (o.a == c.b && o.b == c.a))
          ck.error(e, l, f, fmt::format("{} and {} correlated twice", c.a, c.b));
      s.correlations.push_back(c);
    }

  const YAML::Node ms = root["metrics"];
  if (ms.IsDefined() && ck.expect_seq(ms, 1, "metrics"))
    for (std::size_t i = 0; i < ms.size(); ++i) {
      const std::string f = fmt::format("metrics[{}]", i);
      const YAML::Node e = ms[i];
      if (!ck.expect_map(e, line_of(ms), f)) continue;
      const int l = line_of(e);
      ck.check_keys(e, f, {"name", "column", "stat", "above", "below"});
      Metric m;
      m.line = l;
      for (const char* key : {"name", "column"})
        if (!e[key].IsDefined()) ck.error(l, f + "." + key, "missing");
      if (auto v = e["name"].IsDefined() ? ck.string(e["name"], l, f + ".name") : std::nullopt) m.name = *v;
      if (auto v = e["column"].IsDefined() ? ck.string(e["column"], l, f + ".column") : std::nullopt) m.column = *v;
      std::string stat = "final";
      if (e["stat"].IsDefined())
        if (auto v = ck.string(e["stat"], l, f + ".stat")) stat = *v;
      const std::vector<std::string> stats = {"final", "min", "max", "absmax", "first_time"};
      const auto it = std::find(stats.begin(), stats.end(), stat);
      if (it == stats.end()) {
        ck.error(e["stat"], l, f + ".stat", fmt::format("'{}'{}; expected final, min, max, absmax or first_time", stat, did_you_mean(stat, stats)));
        continue;
      }
      m.stat = static_cast<Metric::Stat>(it - stats.begin());
      if (m.stat == Metric::Stat::first_time) {
        const bool a = e["above"].IsDefined(), b = e["below"].IsDefined();
        if (a == b) ck.error(l, f, "first_time needs exactly one of above: X or below: X");
        else if (auto v = ck.number(e[a ? "above" : "below"], l, f + (a ? ".above" : ".below"))) m.threshold = *v, m.above = a;
      } else if (e["above"].IsDefined() || e["below"].IsDefined()) {
        ck.error(l, f, "above / below apply to stat: first_time only");
      }
      for (const Metric& o : s.metrics)
        if (o.name == m.name) ck.error(e["name"], l, f + ".name", fmt::format("'{}' used twice", m.name));
      s.metrics.push_back(m);
    }
  const YAML::Node ev = root["envelopes"];
  if (ev.IsDefined() && ck.expect_seq(ev, 1, "envelopes"))
    for (std::size_t i = 0; i < ev.size(); ++i)
      if (auto v = ck.string(ev[i], line_of(ev), fmt::format("envelopes[{}]", i))) s.envelopes.push_back(*v);
  if (!diags.empty()) {
    sort_diagnostics(diags);
    throw InputError(diags);
  }
  return s;
}

}  // namespace kanegen
