// `import kanegen`: the Python face of kanegen (pybind11). A Model loads a
// model file and its engine (the generated code through the JIT, or the
// generic engine); eval, outputs and linearize return numpy arrays with their
// names (dicts); simulate takes fixed named inputs or a Python control law
// (t, q, u, y) -> w, continuous or digital, and returns a Run: t, and q, u,
// inputs, outputs as Signals (a 2-D array with its names, indexable by name),
// every column by name, the summary as a dict. Runtime parameters (the
// model's parameters:, every non-zero spring, damper and modal damping ratio,
// and those named when loading) change without a compile: set_parameters or
// parameters= per call. kanegen.sweep runs a sweep file, closed loop with a
// Python law. docs/gnc.md shows the workflow; examples/python/ the LQR example.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <fstream>
#include <sstream>

#include "codegen/assembler.hpp"
#include "codegen/generator.hpp"
#include "codegen/jit_generator.hpp"
#include "engine/generic_engine.hpp"
#include "engine/jit.hpp"
#include "engine/model_checks.hpp"
#include "engine/resources.hpp"
#include "model/diagnostics.hpp"
#include "engine/load_model.hpp"
#include "model/output_file.hpp"
#include "model/parameters.hpp"
#include "model/sweep_spec.hpp"
#include "model/state_io.hpp"
#include "sim/eval_report.hpp"
#include "sim/linearize.hpp"
#include "sim/row_sink.hpp"
#include "sim/simulate.hpp"
#include "sim/sweep.hpp"
#include "view/run_table.hpp"
#include "view/view_data.hpp"
#include "view/view_page.hpp"

namespace py = pybind11;
using namespace kanegen;

namespace {

/// A model and its engine; the Python object owns both.
class PyModel {
 public:
  /// `extra`: model values to keep as runtime parameters besides the model's
  /// own and the implicit ones (a name may stand for several: bus.inertia).
  PyModel(const std::string& path, const std::string& engine, bool native, const std::vector<std::string>& extra)
      : model_(std::make_unique<Model>(with_implicit_parameters(load_model(path)))) {
    for (const std::string& name : extra) {
      std::vector<RuntimeParameter> ps;
      try {
        ps = expand_parameter(*model_, name);
      } catch (const std::invalid_argument& e) {
        throw py::value_error("parameters: " + std::string(e.what()));
      }
      for (const RuntimeParameter& rp : ps) ensure_parameter(*model_, rp);
    }
    check_mass_matrix_at_initial_state(*model_);
    if (engine == "generated") {
      JitOptions o;
      o.native = native;
      engine_ = jit_load(*model_, codegen::jit_code_generator(), o);
    } else if (engine == "generic") {
      engine_ = std::make_unique<GenericEngine>(*model_);
    } else {
      throw py::value_error("engine must be 'generated' or 'generic', not '" + engine + "'");
    }
  }

  const Model& model() const { return *model_; }
  Engine& engine() { return *engine_; }

  /// The engine's runtime parameter values with `values` ({name: value or
  /// [values]}, a name standing for each parameter it expands to) written in.
  VecX parameters_with(const py::dict& values) const {
    VecX p = engine_->parameters();
    for (auto item : values) {
      const std::string name = py::str(item.first);
      std::vector<RuntimeParameter> ps;
      try {
        ps = expand_parameter(*model_, name);
      } catch (const std::invalid_argument& e) {
        throw py::key_error(std::string(e.what()));
      }
      std::vector<double> v;
      if (py::isinstance<py::float_>(item.second) || py::isinstance<py::int_>(item.second))
        v.assign(ps.size(), item.second.cast<double>());
      else
        v = item.second.cast<std::vector<double>>();
      if (v.size() != ps.size())
        throw py::value_error(name + ": " + std::to_string(v.size()) + " values; it stands for " +
                              std::to_string(ps.size()) + " (give one value for all, or " + std::to_string(ps.size()) + ")");
      for (std::size_t k = 0; k < ps.size(); ++k) {
        const int i = find_parameter(model_->parameters, ps[k].kind, ps[k].body, ps[k].index);
        if (i < 0)
          throw py::key_error(ps[k].name + " is not a runtime parameter of this model: name it when loading, "
                              "kanegen.Model(path, parameters=['" + name + "']) (one compile), or under parameters: "
                              "in the model file");
        p(i) = v[k];
      }
    }
    return p;
  }
  void set_parameters(const VecX& p) {
    try {
      engine_->set_parameters(p);
    } catch (const std::invalid_argument& e) {
      throw py::value_error(e.what());
    }
  }

  /// A state from optional arrays or {name: value} dicts (missing: the model's initial state).
  State state(double t, const py::object& q, const py::object& u, const py::object& tau,
              const py::object& inputs) const {
    State s = initial_state(*model_);
    s.t = t;
    fill(q, model_->q_names, s.q, "q");
    fill(u, model_->u_names, s.u, "u", model_.get());
    fill(tau, model_->u_names, s.tau, "tau", model_.get());
    fill(inputs, model_->input_names, s.w, "inputs");
    for (const auto& slot : model_->quaternions) {
      auto quat = s.q.segment<4>(slot.q);
      if (!(quat.norm() > 0)) throw py::value_error("q: quaternion of '" + model_->bodies[slot.body].name + "' is zero");
      quat.normalize();
    }
    return s;
  }

  /// `locked`: the bodies whose joints are locked at the state (None: the
  /// model's `locked: true` joints), as STATE.json's "locked".
  void apply_locked(State& s, const py::object& locked) const {
    if (locked.is_none()) return;
    std::fill(s.locked.begin(), s.locked.end(), 0);
    for (const auto& item : locked.cast<std::vector<std::string>>()) {
      const int b = model_->body_index(item);
      if (b < 0) throw py::key_error("locked: no body named '" + item + "'");
      if (!joint_can_lock(model_->bodies[b].joint))
        throw py::value_error("locked: the joint of '" + item + "' has no degree of freedom to lock");
      s.locked[b] = 1;
    }
    for (int k : locked_speeds(*model_, s.locked))
      if (s.u(k) != 0.0) throw py::value_error("locked: '" + model_->u_names[k] + "' is not 0 but its joint is locked");
  }

 private:
  /// `speeds`: the model when the names are speeds (the older names accepted, model-format.md).
  static void fill(const py::object& v, const std::vector<std::string>& names, VecX& out, const char* what,
                   const Model* speeds = nullptr) {
    if (v.is_none()) return;
    if (py::isinstance<py::dict>(v)) {
      std::vector<std::string> given(out.size());
      for (auto item : v.cast<py::dict>()) {
        const std::string n = py::str(item.first);
        const auto it = std::find(names.begin(), names.end(), n);
        const int k = speeds ? speeds->speed_index(n) : it == names.end() ? -1 : static_cast<int>(it - names.begin());
        if (k < 0) throw py::key_error(std::string(what) + ": unknown name '" + n + "'");
        if (!given[k].empty())
          throw py::key_error(std::string(what) + ": '" + given[k] + "' and '" + n + "' name the same speed");
        given[k] = n;
        out(k) = item.second.cast<double>();
      }
      return;
    }
    const VecX a = v.cast<VecX>();
    if (a.size() != out.size())
      throw py::value_error(std::string(what) + ": " + std::to_string(a.size()) + " values; expected " +
                            std::to_string(out.size()));
    out = a;
  }
  std::unique_ptr<Model> model_;
  std::unique_ptr<Engine> engine_;
};

/// Per-call parameter values (`parameters=`), the engine's own back afterwards.
class ScopedParameters {
 public:
  ScopedParameters(PyModel& m, const py::object& values) : m_(m), saved_(m.engine().parameters()) {
    if (values.is_none()) return;
    m_.set_parameters(m_.parameters_with(values.cast<py::dict>()));
    active_ = true;
  }
  ~ScopedParameters() {
    if (active_) m_.engine().set_parameters(saved_);
  }

 private:
  PyModel& m_;
  VecX saved_;
  bool active_ = false;
};

/// Named columns of a run: a 2-D array (rows x names) that reads like a dict
/// of 1-D arrays (signals["bus.qw"], keys(), items(), in).
struct Signals {
  std::vector<std::string> names;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> values;
  int index(const std::string& n) const {
    const auto it = std::find(names.begin(), names.end(), n);
    return it == names.end() ? -1 : static_cast<int>(it - names.begin());
  }
  VecX column(const std::string& n) const {
    const int k = index(n);
    if (k < 0) throw py::key_error("no signal named '" + n + "'");
    return values.col(k);
  }
};

/// A run's results as data: taken from the rows simulate() gives (RowTable), never from text.
struct Run {
  VecX t;
  Signals q, u, inputs, outputs, all;
  py::dict summary;
  py::list events;
  std::shared_ptr<const Model> model;  ///< the model it ran (for view())
  std::vector<RunEvent> fired;         ///< its events as the view reads them
};

Signals signals_of(const RowTable& table, const std::vector<std::string>& names) {
  Signals s;
  for (const auto& n : names)
    if (table.column_index(n) >= 0) s.names.push_back(n);
  s.values.resize(static_cast<Eigen::Index>(table.rows()), static_cast<Eigen::Index>(s.names.size()));
  for (std::size_t c = 0; c < s.names.size(); ++c) {
    const int k = table.column_index(s.names[c]);
    for (std::size_t r = 0; r < table.rows(); ++r)
      s.values(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = table.at(r, static_cast<std::size_t>(k));
  }
  return s;
}

py::dict named(const std::vector<std::string>& names, const VecX& v) {
  py::dict d;
  for (std::size_t i = 0; i < names.size(); ++i) d[py::str(names[i])] = v(static_cast<Eigen::Index>(i));
  return d;
}

py::dict linear_dict(const LinearModel& lin) {
  py::dict d;
  d["A"] = lin.A;
  d["B"] = lin.B;
  d["C"] = lin.C;
  d["D"] = lin.D;
  d["x0_dot"] = lin.x0_dot;
  d["y0"] = lin.y0;
  d["state_names"] = lin.state_names;
  d["input_names"] = lin.input_names;
  d["output_names"] = lin.output_names;
  d["equilibrium"] = lin.equilibrium;
  d["relative_equilibrium"] = lin.relative_equilibrium;
  d["ignorable"] = lin.ignorable;
  d["ignorable_kept_for_outputs"] = lin.ignorable_kept_for_outputs;
  d["residual"] = lin.residual;
  d["method"] = lin.method;
  d["frame"] = lin.frame;
  py::list modes;
  for (const LinearMode& m : linear_modes(lin)) {
    py::dict md;
    md["eigenvalue"] = m.eigenvalue;
    md["natural_frequency_hz"] = m.natural_frequency_hz;
    md["damped_frequency_hz"] = m.damped_frequency_hz;
    md["damping_ratio"] = m.damping_ratio;
    md["zero"] = m.zero;
    md["dominant_states"] = m.dominant_states;
    modes.append(md);
  }
  d["modes"] = modes;
  return d;
}

/// A Python control law (t, q, u, y) -> w as a Controller.
Controller python_controller(const py::object& law, double period, int nw) {
  Controller c;
  if (law.is_none()) return c;
  py::function f = law.cast<py::function>();
  c.period = period;
  c.law = [f, nw](double t, const VecX& qq, const VecX& uu, const VecX& y, VecX& w) {
    py::object r = f(t, qq, uu, y);
    const VecX v = r.cast<VecX>();
    if (v.size() != nw)
      throw py::value_error("controller returned " + std::to_string(v.size()) + " inputs; expected " + std::to_string(nw));
    w = v;
  };
  return c;
}

Run make_run(const RowTable& table, const SimulationResult& r, const Model& m) {
  Run run;
  run.t = table.rows() ? VecX(Eigen::Map<const VecX>(table.column(0).data(), static_cast<Eigen::Index>(table.rows())))
                       : VecX();
  std::vector<std::string> names = table.columns();
  for (std::size_t i = 0; i < names.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (names[i] == names[j]) throw std::runtime_error("simulate: column '" + names[i] + "' named twice");
  run.all = signals_of(table, names);
  run.q = signals_of(table, m.q_names);
  run.u = signals_of(table, m.u_names);
  run.inputs = signals_of(table, m.input_names);
  run.outputs = signals_of(table, m.output_names);
  py::dict& d = run.summary;
  d["integrator"] = r.stats.integrator;
  d["integrator_choice"] = r.quality.integrator_choice;
  d["steps"] = r.stats.steps;
  d["rhs_evals"] = r.stats.rhs_evals;
  d["jac_evals"] = r.stats.jac_evals;
  d["wall_seconds"] = r.stats.wall_seconds;
  d["rows"] = r.rows;
  d["segments"] = r.segments;
  d["max_quaternion_drift"] = r.max_quaternion_drift;
  d["energy_drift"] = r.quality.energy_drift;  // NaN: not an invariant of the scene
  d["energy_balance"] = r.quality.energy_balance;  // E - E0 - drivers' work (prescribed motion), NaN otherwise
  d["H_drift"] = r.quality.H_drift;
  d["energy_drift_J"] = r.quality.energy_drift_J;  // the same drifts in their units (docs/decisions.md)
  d["H_drift_Nms"] = r.quality.H_drift_Nms;
  d["drift_about_centre_of_mass"] = r.quality.about_com;  // relative to the motion about the centre of mass
  d["H_z_only"] = r.quality.H_z;
  d["error_estimate"] = r.quality.error_estimate;
  d["error_worst"] = r.quality.error_worst;
  d["accuracy"] = r.quality.summary();
  d["warnings"] = r.quality.warnings;
  d["text"] = r.stats.summary();
  for (const FiredEvent& e : r.events) {  // model-format.md, Locks and events
    py::dict ev;
    ev["t"] = e.t;
    ev["name"] = e.name;
    ev["action"] = e.action;
    ev["bodies"] = e.bodies;
    ev["energy_lost"] = e.energy_lost;
    ev["u_before"] = e.u_before;
    ev["u_after"] = e.u_after;
    run.events.append(ev);
    RunEvent re{e.t, e.name, e.action, {}};
    std::istringstream bodies(e.bodies);
    for (std::string b; bodies >> b;) re.bodies.push_back(b);
    run.fired.push_back(std::move(re));
  }
  d["events"] = run.events;
  run.model = std::make_shared<const Model>(m);
  return run;
}

/// `kanegen view`'s page of a model (run null: its initial state) or of a run, written to `path` (view/).
std::string write_view(const Model& model, const Run* run, const std::string& path, int frames,
                       const std::vector<std::string>& columns) {
  if (frames < 1) throw py::value_error("frames: " + std::to_string(frames) + "; expected at least 1");
  ViewOptions vo;
  vo.frames = frames;
  vo.columns = columns;
  RunTable table;
  if (run) {
    table.path = "the run";
    table.names = run->all.names;
    table.rows = run->all.values;
    vo.events = &run->fired;
  }
  const nlohmann::json data = view_data(model, run ? &table : nullptr, vo, "the run's events");
  write_file_atomically(path, view_page(data));
  return path;
}

template <class F>
auto translating(F&& f) {
  try {
    return f();
  } catch (const InputError& e) {
    std::string msg;
    for (const Diagnostic& d : e.diagnostics()) msg += (msg.empty() ? "" : "\n") + d.str();
    throw py::value_error(msg);
  } catch (const IntegrationError& e) {
    throw std::runtime_error(e.what());
  }
}

}  // namespace

PYBIND11_MODULE(kanegen, m) {
  m.doc() = "kanegen: Kane's-method equations of motion for multibody spacecraft (docs/gnc.md)";
  py::register_exception<SingularMassMatrix>(m, "SingularMassMatrix", PyExc_ArithmeticError);

  py::class_<Signals>(m, "Signals", "named columns of a run: values (rows x names), names; s[name] is a column")
      .def_readonly("names", &Signals::names)
      .def_property_readonly("values", [](const Signals& s) { return s.values; })
      .def("__getitem__", &Signals::column)
      .def("__contains__", [](const Signals& s, const std::string& n) { return s.index(n) >= 0; })
      .def("__len__", [](const Signals& s) { return s.names.size(); })
      .def("__iter__", [](const Signals& s) { return py::iter(py::cast(s.names)); })
      .def("keys", [](const Signals& s) { return s.names; })
      .def("items", [](const Signals& s) {
        py::list l;
        for (const auto& n : s.names) l.append(py::make_tuple(n, s.column(n)));
        return l;
      })
      .def("__repr__", [](const Signals& s) {
        return "Signals(" + std::to_string(s.values.rows()) + " rows: " +
               (s.names.size() > 6 ? std::to_string(s.names.size()) + " names" : [&] {
                 std::string j;
                 for (const auto& n : s.names) j += (j.empty() ? "" : ", ") + n;
                 return j;
               }()) + ")";
      });
  py::class_<Run>(m, "Run", "a simulation's results: t, q, u, inputs, outputs (Signals), columns, summary, events")
      .def_readonly("t", &Run::t)
      .def_readonly("q", &Run::q)
      .def_readonly("u", &Run::u)
      .def_readonly("inputs", &Run::inputs)
      .def_readonly("outputs", &Run::outputs)
      .def_readonly("summary", &Run::summary)
      .def_readonly("events", &Run::events)
      .def_property_readonly("columns", [](const Run& r) {
        py::dict d;  // in the CSV's order: pandas.DataFrame(run.columns)
        for (const auto& n : r.all.names) d[py::str(n)] = r.all.column(n);
        return d;
      }, "{column: array} of every column of `kanegen simulate`'s CSV, in its order (pandas.DataFrame(run.columns))")
      .def("__getitem__", [](const Run& r, const std::string& n) { return r.all.column(n); }, "a column by name")
      .def("__contains__", [](const Run& r, const std::string& n) { return r.all.index(n) >= 0; })
      .def("__len__", [](const Run& r) { return r.t.size(); })
      .def("view", [](const Run& r, const std::string& path, int frames, const std::vector<std::string>& columns) {
             return translating([&] { return write_view(*r.model, &r, path, frames, columns); });
           }, py::arg("path"), py::arg("frames") = 500, py::arg("columns") = std::vector<std::string>{},
           "writes kanegen view's page of this run to path (one offline HTML file: docs/view.md): bodies, joints, "
           "flexible nodes, a time slider, the events named, `columns` plotted (default: T, V and the root's "
           "speeds); at most `frames` frames; returns path")
      .def("__repr__", [](const Run& r) {
        return "Run(" + std::to_string(r.t.size()) + " rows, " + std::to_string(r.all.names.size()) + " columns)";
      });

  py::class_<PyModel>(m, "Model")
      .def(py::init([](const std::string& path, const std::string& engine, bool native,
                       const std::vector<std::string>& parameters) {
             return translating([&] { return std::make_unique<PyModel>(path, engine, native, parameters); });
           }),
           py::arg("path"), py::arg("engine") = "generated", py::arg("native") = false,
           py::arg("parameters") = std::vector<std::string>{},
           "Loads a model file; engine 'generated' (JIT-compiled, cached) or 'generic'; parameters: model values "
           "to keep as runtime parameters besides the model's own and its springs, dampers and damping ratios "
           "(bus.mass, bus.inertia, ...: model-format.md)")
      .def("view", [](const PyModel& p, const std::string& path) {
             return translating([&] { return write_view(p.model(), nullptr, path, 1, {}); });
           }, py::arg("path"),
           "writes kanegen view's page of the model at its initial state to path (its 3D sanity check: "
           "docs/view.md); returns path")
      .def_property_readonly("parameter_names", [](const PyModel& p) {
        std::vector<std::string> n;
        for (const RuntimeParameter& rp : p.model().parameters) n.push_back(rp.name);
        return n;
      }, "the runtime parameters: values set_parameters changes without a compile")
      .def_property_readonly("parameters", [](PyModel& p) {
        py::dict d;
        for (std::size_t i = 0; i < p.model().parameters.size(); ++i)
          d[py::str(p.model().parameters[i].name)] = p.engine().parameters()(static_cast<Eigen::Index>(i));
        return d;
      }, "{name: value} of the runtime parameters now")
      .def("set_parameters", [](PyModel& p, const py::dict& values) { p.set_parameters(p.parameters_with(values)); },
           py::arg("values"),
           "sets runtime parameters, {name: value}; a name standing for several (array.damping_ratio: every "
           "mode's, bus.inertia: six) takes one value for all or a list; no compile")
      .def_property_readonly("name", [](const PyModel& p) { return p.model().name; })
      .def_property_readonly("engine", [](PyModel& p) { return p.engine().name(); })
      .def_property_readonly("q_names", [](const PyModel& p) { return p.model().q_names; })
      .def_property_readonly("u_names", [](const PyModel& p) { return p.model().u_names; })
      .def_property_readonly("input_names", [](const PyModel& p) { return p.model().input_names; })
      .def_property_readonly("output_names", [](const PyModel& p) { return p.model().output_names; })
      .def_property_readonly("nq", [](const PyModel& p) { return p.model().nq; })
      .def_property_readonly("nu", [](const PyModel& p) { return p.model().nu; })
      .def_property_readonly("nw", [](const PyModel& p) { return p.model().nw; })
      .def_property_readonly("ny", [](const PyModel& p) { return p.model().ny; })
      .def_property_readonly("q0", [](const PyModel& p) { return initial_state(p.model()).q; })
      .def_property_readonly("u0", [](const PyModel& p) { return initial_state(p.model()).u; })
      .def(
          "eval",
          [](PyModel& p, const py::object& q, const py::object& u, const py::object& tau, const py::object& inputs,
             double t, const py::object& locked, const py::object& parameters) {
            const ScopedParameters with(p, parameters);
            State s = p.state(t, q, u, tau, inputs);
            p.apply_locked(s, locked);
            const ScopedLocks locks(p.engine(), s.locked);  // u_dot: the reduced system's while locked
            p.engine().set_inputs(s.w);
            VecX qd, F, ud, y;
            MatX M;
            p.engine().qdot(s.q, s.u, qd);
            p.engine().mass_matrix(s.t, s.q, M);
            p.engine().forcing(s.t, s.q, s.u, s.tau, F);
            p.engine().udot(s.t, s.q, s.u, s.tau, ud);
            py::dict d;
            d["qdot"] = qd;
            d["M"] = M;
            d["F"] = F;
            d["udot"] = ud;
            if (p.model().ny) {
              p.engine().outputs(s.t, s.q, s.u, s.tau, y);
              d["outputs"] = named(p.model().output_names, y);
            }
            d["q_names"] = p.model().q_names;
            d["u_names"] = p.model().u_names;
            return d;
          },
          py::arg("q") = py::none(), py::arg("u") = py::none(), py::arg("tau") = py::none(),
          py::arg("inputs") = py::none(), py::arg("t") = 0.0, py::arg("locked") = py::none(),
          py::arg("parameters") = py::none(),
          "q_dot, M, F, u_dot and the named outputs at a state (arrays or {name: value}; missing: the initial state); "
          "locked: bodies whose joints are locked there (default: the model's locked: true)")
      .def(
          "outputs",
          [](PyModel& p, const py::object& q, const py::object& u, const py::object& tau, const py::object& inputs,
             double t) {
            const State s = p.state(t, q, u, tau, inputs);
            p.engine().set_inputs(s.w);
            VecX y;
            p.engine().outputs(s.t, s.q, s.u, s.tau, y);
            return y;
          },
          py::arg("q") = py::none(), py::arg("u") = py::none(), py::arg("tau") = py::none(),
          py::arg("inputs") = py::none(), py::arg("t") = 0.0, "the named outputs y as an array (output_names)")
      .def(
          "linearize",
          [](PyModel& p, const py::object& q, const py::object& u, const py::object& tau, const py::object& inputs,
             double t, const std::vector<std::string>& input_names, const std::vector<std::string>& output_names,
             bool finite_differences, const py::object& parameters, bool drop_ignorable, const std::string& frame) {
            return translating([&] {
              const ScopedParameters with(p, parameters);
              LinearizeOptions o;
              o.inputs = input_names;
              o.outputs = output_names;
              o.finite_differences = finite_differences;
              o.drop_ignorable = drop_ignorable;
              o.frame = frame;
              return linear_dict(linearize(p.engine(), p.state(t, q, u, tau, inputs), o));
            });
          },
          py::arg("q") = py::none(), py::arg("u") = py::none(), py::arg("tau") = py::none(),
          py::arg("inputs") = py::none(), py::arg("t") = 0.0, py::arg("input_names") = std::vector<std::string>{},
          py::arg("output_names") = std::vector<std::string>{}, py::arg("finite_differences") = false,
          py::arg("parameters") = py::none(), py::arg("drop_ignorable") = false, py::arg("frame") = "inertial",
          "continuous-time A, B, C, D about a state (tangent-space attitude), with names and modes; "
          "frame=\"lvlh\": the free root relative to the orbit frame (docs/gnc.md, \"Linear models in orbit\")")
      .def(
          "simulate",
          [](PyModel& p, double t_end, double dt_out, const py::object& q, const py::object& u, const py::object& tau,
             const py::object& inputs, const py::object& controller, double period, const std::string& integrator,
             double rtol, double atol, double h, const py::object& locked, const py::object& parameters,
             bool estimate_error) {
            return translating([&] {
              State s = p.state(0.0, q, u, tau, inputs);
              p.apply_locked(s, locked);
              SimulationOptions o;
              o.t_end = t_end;
              o.dt_out = dt_out;
              o.integrator.kind = integrator_from_string(integrator);
              o.integrator.rtol = rtol;
              o.integrator.atol = atol;
              o.integrator.h = h;
              o.controller = python_controller(controller, period, p.model().nw);
              o.estimate_error = estimate_error;
              const ScopedParameters with(p, parameters);
              RowTable table;
              const SimulationResult r = simulate(p.engine(), s, o, table);
              return make_run(table, r, p.model());
            });
          },
          py::arg("t_end"), py::arg("dt_out") = 0.01, py::arg("q") = py::none(), py::arg("u") = py::none(),
          py::arg("tau") = py::none(), py::arg("inputs") = py::none(), py::arg("controller") = py::none(),
          py::arg("period") = 0.0, py::arg("integrator") = "auto", py::arg("rtol") = 1e-10,
          py::arg("atol") = 1e-12, py::arg("h") = 1e-3, py::arg("locked") = py::none(),
          py::arg("parameters") = py::none(), py::arg("estimate_error") = false,
          "integrates from a state (locked: the bodies whose joints start locked; default the model's); inputs "
          "fixed, or set by controller(t, q, u, y) -> w (continuous when period is 0, else digital with "
          "zero-order hold); h is rk4's step; parameters: {name: value} for this run only. Returns a Run: t, q, "
          "u, inputs, outputs (Signals by name), columns (every column of `kanegen simulate`'s CSV), summary "
          "(integrator and why, steps, drifts, events), events");

  m.def(
      "sweep",
      [](const std::string& path, const py::object& controller, double period, const std::string& output,
         const std::string& engine) {
        return translating([&] {
          const SweepPlan plan = plan_sweep(load_sweep_spec(path));
          if (!output.empty()) check_sweep_output_directory("output", output);  // before any run
          const std::string which = engine.empty() ? plan.spec.engine : engine;
          std::unique_ptr<Engine> e;
          if (which == "generated") e = jit_load(plan.model, codegen::jit_code_generator(), JitOptions{});
          else if (which == "generic") e = std::make_unique<GenericEngine>(plan.model);
          else throw py::value_error("engine must be 'generated' or 'generic', not '" + which + "'");
          ControllerFactory law;
          if (!controller.is_none())
            law = [&](const Model& m, long) { return python_controller(controller, period, m.nw); };
          std::vector<RunResult> results;
          for (long k = 0; k < plan.spec.runs; ++k) results.push_back(run_one(*e, plan, k, nullptr, law));
          if (!output.empty()) write_sweep_outputs(plan, results, output);
          py::dict d;
          VecX run(static_cast<Eigen::Index>(results.size()));
          py::list status;
          for (std::size_t k = 0; k < results.size(); ++k) run(static_cast<Eigen::Index>(k)) = results[k].index, status.append(results[k].status);
          d["run"] = run;
          d["status"] = status;
          auto table = [&](const std::vector<std::string>& names, auto get) {
            py::dict t;
            for (std::size_t i = 0; i < names.size(); ++i) {
              VecX v(static_cast<Eigen::Index>(results.size()));
              for (std::size_t k = 0; k < results.size(); ++k) v(static_cast<Eigen::Index>(k)) = get(results[k], i);
              t[py::str(names[i])] = v;
            }
            return t;
          };
          std::vector<std::string> dn, mn;
          for (const auto& x : plan.spec.dispersions) dn.push_back(x.target);
          for (const auto& x : plan.spec.metrics) mn.push_back(x.name);
          d["values"] = table(dn, [](const RunResult& r, std::size_t i) { return r.values[i]; });
          d["metrics"] = table(mn, [](const RunResult& r, std::size_t i) { return r.metrics.empty() ? NAN : r.metrics[i]; });
          double wall = 0;
          for (const auto& r : results) wall += r.wall_s;
          d["wall_seconds"] = wall;
          return d;
        });
      },
      py::arg("sweep"), py::arg("controller") = py::none(), py::arg("period") = 0.0, py::arg("output") = "",
      py::arg("engine") = "",
      "runs a sweep file (docs/sweeps.md) in this process, closed loop when controller(t, q, u, y) -> w is given "
      "(continuous when period is 0, else digital); output: a directory for runs.csv, summary.json, ... as "
      "`kanegen sweep` writes them (byte-identical for the same runs); returns {run, status, values: {name: "
      "array}, metrics: {name: array}, wall_seconds}");

  m.def(
      "generate",
      [](const std::string& model_path, const std::string& header_path) {
        translating([&] {
          const Model model = load_model(model_path);
          const codegen::EmittedModel em = codegen::generate(model);
          write_file_atomically(header_path, codegen::assemble(em, template_dir(), header_path).header);
          return 0;
        });
      },
      py::arg("model"), py::arg("header"), "writes the model's generated header (as `kanegen generate`)");
}
