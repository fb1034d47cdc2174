// `import kanegen`: the Python face of kanegen (pybind11). A Model loads a
// model file and its engine (the generated code through the JIT, or the
// generic engine); eval, outputs, linearize and simulate return numpy arrays
// with their names (dicts); simulate takes fixed named inputs or a Python
// control law (t, q, u, y) -> w, continuous or digital. docs/gnc.md shows
// the workflow; examples/python/ the LQR example.
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
#include "model/model_loader.hpp"
#include "model/output_file.hpp"
#include "model/state_io.hpp"
#include "sim/eval_report.hpp"
#include "sim/linearize.hpp"
#include "sim/simulate.hpp"

namespace py = pybind11;
using namespace kanegen;

namespace {

/// A model and its engine; the Python object owns both.
class PyModel {
 public:
  PyModel(const std::string& path, const std::string& engine, bool native)
      : model_(std::make_unique<Model>(load_model(path))) {
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
  d["residual"] = lin.residual;
  d["method"] = lin.method;
  py::list modes;
  for (const LinearMode& m : linear_modes(lin)) {
    py::dict md;
    md["eigenvalue"] = m.eigenvalue;
    md["natural_frequency_hz"] = m.natural_frequency_hz;
    md["damped_frequency_hz"] = m.damped_frequency_hz;
    md["damping_ratio"] = m.damping_ratio;
    md["dominant_states"] = m.dominant_states;
    modes.append(md);
  }
  d["modes"] = modes;
  return d;
}

/// The CSV of a run as {column: array}, plus "columns" (their order); a
/// repeated column name is refused (it would hide the other column).
py::dict columns_of(const std::string& csv) {
  std::istringstream in(csv);
  std::string header, line;
  std::getline(in, header);
  std::vector<std::string> cols;
  for (std::size_t a = 0, b; a <= header.size(); a = b + 1) {
    b = header.find(',', a);
    if (b == std::string::npos) b = header.size();
    cols.push_back(header.substr(a, b - a));
  }
  std::vector<std::vector<double>> data(cols.size());
  while (std::getline(in, line)) {
    const char* p = line.c_str();
    for (std::size_t c = 0; c < cols.size(); ++c) {
      char* end = nullptr;
      data[c].push_back(std::strtod(p, &end));
      p = *end == ',' ? end + 1 : end;
    }
  }
  py::dict d;
  for (std::size_t c = 0; c < cols.size(); ++c) {
    if (d.contains(py::str(cols[c]))) throw std::runtime_error("simulate: column '" + cols[c] + "' named twice");
    d[py::str(cols[c])] = py::array_t<double>(data[c].size(), data[c].data());
  }
  d["columns"] = cols;
  return d;
}

/// The named groups of a run's columns: "q", "u", "inputs", "outputs" as
/// {name: array} (each name once), beside the flat columns.
void add_groups(py::dict& d, const Model& m) {
  auto group = [&](const std::vector<std::string>& names) {
    py::dict g;
    for (const auto& n : names)
      if (d.contains(py::str(n))) g[py::str(n)] = d[py::str(n)];
    return g;
  };
  d["q"] = group(m.q_names);
  d["u"] = group(m.u_names);
  d["inputs"] = group(m.input_names);
  d["outputs"] = group(m.output_names);
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

  py::class_<PyModel>(m, "Model")
      .def(py::init([](const std::string& path, const std::string& engine, bool native) {
             return translating([&] { return std::make_unique<PyModel>(path, engine, native); });
           }),
           py::arg("path"), py::arg("engine") = "generated", py::arg("native") = false,
           "Loads a model file; engine 'generated' (JIT-compiled, cached) or 'generic'.")
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
             double t, const py::object& locked) {
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
             bool finite_differences) {
            return translating([&] {
              LinearizeOptions o;
              o.inputs = input_names;
              o.outputs = output_names;
              o.finite_differences = finite_differences;
              return linear_dict(linearize(p.engine(), p.state(t, q, u, tau, inputs), o));
            });
          },
          py::arg("q") = py::none(), py::arg("u") = py::none(), py::arg("tau") = py::none(),
          py::arg("inputs") = py::none(), py::arg("t") = 0.0, py::arg("input_names") = std::vector<std::string>{},
          py::arg("output_names") = std::vector<std::string>{}, py::arg("finite_differences") = false,
          "continuous-time A, B, C, D about a state (tangent-space attitude), with names and modes")
      .def(
          "simulate",
          [](PyModel& p, double t_end, double dt_out, const py::object& q, const py::object& u, const py::object& tau,
             const py::object& inputs, const py::object& controller, double period, const std::string& integrator,
             double rtol, double atol, double h, const py::object& locked) {
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
              if (!controller.is_none()) {
                py::function f = controller.cast<py::function>();
                const int nw = p.model().nw;
                o.controller.period = period;
                o.controller.law = [f, nw](double t, const VecX& qq, const VecX& uu, const VecX& y, VecX& w) {
                  py::object r = f(t, qq, uu, y);
                  const VecX v = r.cast<VecX>();
                  if (v.size() != nw)
                    throw py::value_error("controller returned " + std::to_string(v.size()) +
                                          " inputs; expected " + std::to_string(nw));
                  w = v;
                };
              }
              std::ostringstream csv;
              const SimulationResult r = simulate(p.engine(), s, o, csv);
              py::dict d = columns_of(csv.str());
              add_groups(d, p.model());
              d["summary"] = r.stats.summary();
              d["rhs_evals"] = r.stats.rhs_evals;
              d["steps"] = r.stats.steps;
              d["wall_seconds"] = r.stats.wall_seconds;
              py::list events;  // the events that fired (model-format.md, Locks and events)
              for (const FiredEvent& e : r.events) {
                py::dict ev;
                ev["t"] = e.t;
                ev["name"] = e.name;
                ev["action"] = e.action;
                ev["bodies"] = e.bodies;
                ev["energy_lost"] = e.energy_lost;
                ev["u_before"] = e.u_before;
                ev["u_after"] = e.u_after;
                events.append(ev);
              }
              d["events"] = events;
              return d;
            });
          },
          py::arg("t_end"), py::arg("dt_out") = 0.01, py::arg("q") = py::none(), py::arg("u") = py::none(),
          py::arg("tau") = py::none(), py::arg("inputs") = py::none(), py::arg("controller") = py::none(),
          py::arg("period") = 0.0, py::arg("integrator") = "auto", py::arg("rtol") = 1e-10,
          py::arg("atol") = 1e-12, py::arg("h") = 1e-3, py::arg("locked") = py::none(),
          "integrates from a state (locked: the bodies whose joints start locked; default the model's); inputs fixed, or set by controller(t, q, u, y) -> w (continuous when period "
          "is 0, else digital with zero-order hold); h is rk4's step; returns {column: array} as the CSV of "
          "`kanegen simulate`, plus 'events': the events that fired (t, name, action, bodies, energy_lost, "
          "u_before, u_after)");

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
