#include "codegen/assembler.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>


namespace kanegen::codegen {

namespace {

std::string read_template(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read template " + path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void replace_all(std::string& s, const std::string& key, const std::string& value) {
  const std::string k = "{{" + key + "}}";
  for (std::size_t pos = s.find(k); pos != std::string::npos; pos = s.find(k, pos + value.size()))
    s.replace(pos, k.size(), value);
}

std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
  return s;
}

/// A C string literal's contents.
std::string escaped(const std::string& s) {
  std::string r;
  for (char c : s) {
    if (c == '\\' || c == '"') r += '\\';
    r += c;
  }
  return r;
}

const char* arg_name(Arg a) {
  switch (a) {
    case Arg::t: return "t";
    case Arg::q: return "q";
    case Arg::u: return "u";
    case Arg::tau: return "tau";
    case Arg::udot_in: return "udot_in";
    case Arg::inputs: return "inputs";
    case Arg::params: return "prm";
    case Arg::out: return "out";
  }
  return "?";
}

/// C++ parameter list of a function in the header.
std::string parameters(const EmittedFunction& f) {
  const std::string T = f.templated ? "T" : "double";
  std::vector<std::string> ps;
  for (Arg a : f.args) {
    if (a == Arg::t)
      ps.push_back("const double t");
    else if (a == Arg::params)
      ps.push_back("const double* prm");
    else if (a == Arg::out)
      ps.push_back(fmt::format("{}* {}", T, f.out_name));
    else
      ps.push_back(fmt::format("const {}* {}", T, arg_name(a)));
  }
  return join(ps, ", ");
}

/// Arguments of the call from the C wrapper: taken from KanegenArgs* a.
std::string call_arguments(const EmittedFunction& f) {
  std::vector<std::string> as;
  for (Arg a : f.args) {
    switch (a) {
      case Arg::t: as.push_back("a->t"); break;
      case Arg::q: as.push_back("a->q"); break;
      case Arg::u: as.push_back("a->u"); break;
      case Arg::tau: as.push_back("a->tau"); break;
      case Arg::udot_in: as.push_back("a->udot"); break;
      case Arg::inputs: as.push_back("a->inputs"); break;
      case Arg::params: as.push_back("a->params"); break;
      case Arg::out: as.push_back("out"); break;
    }
  }
  return join(as, ", ");
}

/// Argument names of f, in order (the output array's too), for the calls of its parts.
std::string argument_names(const EmittedFunction& f) {
  std::vector<std::string> as;
  for (Arg a : f.args) as.push_back(a == Arg::out ? f.out_name : arg_name(a));
  return join(as, ", ");
}

/// The helper functions of a function emitted in parts.
std::string parts_text(const EmittedFunction& f) {
  std::string s;
  std::vector<std::string> unused;
  for (Arg a : f.args)
    if (a != Arg::out) unused.push_back(fmt::format("(void){};", arg_name(a)));
  for (std::size_t i = 0; i < f.parts.size(); ++i) {
    s += fmt::format("\n// {}, part {} of {}\ntemplate <class T>\nKANEGEN_NOINLINE KANEGEN_DISPATCH void {}_part{}({}, T* w) {{\n",
                     f.name, i + 1, f.parts.size() + 1, f.name, i, parameters(f));
    s += "  using std::cos; using std::sin; using std::sqrt;\n";
    s += "  " + join(unused, " ") + " (void)" + f.out_name + "; (void)w;\n";
    s += f.parts[i];
    s += "}\n";
  }
  return s;
}

/// The kernels of a compact function (outlined_code.hpp).
std::string kernels_text(const EmittedFunction& f) {
  std::string s;
  for (std::size_t i = 0; i < f.kernels.size(); ++i) {
    s += fmt::format("\n// {}, kernel {} of {}\ntemplate <class T>\nKANEGEN_NOINLINE KANEGEN_DISPATCH void "
                     "{}_kernel{}(T* w, const int* x, const double* c) {{\n",
                     f.name, i + 1, f.kernels.size(), f.name, i);
    s += "  using std::cos; using std::sin; using std::sqrt;\n  (void)c;\n";
    s += f.kernels[i];
    s += "}\n";
  }
  return s + "\n" + f.kernel_tables;
}

std::string function_text(const EmittedFunction& f) {
  std::string s = fmt::format("\n// ---- {} {}\n", f.title, std::string(f.title.size() < 74 ? 74 - f.title.size() : 3, '-'));
  if (!f.parts.empty()) s += parts_text(f) + "\n";
  if (!f.kernels.empty())
    s += fmt::format("\n// Compact code: {} kernels, {} calls, one per group of a body's code (outlined_code.hpp)\n",
                     f.kernels.size(), f.kernel_calls) +
         kernels_text(f) + "\n";
  s += f.note;
  if (f.templated) s += "template <class T>\n";
  s += fmt::format("{}{} {}({}) {{\n", f.templated ? "" : "inline ", f.returns_status ? "int" : "void", f.name,
                   parameters(f));
  if (f.templated) s += "  using std::cos; using std::sin; using std::sqrt;\n";
  std::vector<std::string> unused;
  for (Arg a : f.args)
    if (a != Arg::out) unused.push_back(fmt::format("(void){};", arg_name(a)));
  if (!unused.empty() && f.templated) s += "  " + join(unused, " ") + "\n";
  if (!f.parts.empty()) {
    // the parts' workspace: a fixed-size array on the caller's stack (the
    // Jacobian's dual numbers carry one direction, so it stays small)
    s += fmt::format("  T w[{}];\n", std::max(1, f.workspace));
    for (std::size_t i = 0; i < f.parts.size(); ++i)
      s += fmt::format("  {}_part{}({}, w);\n", f.name, i, argument_names(f));
  }
  s += f.body;
  if (f.returns_status && f.templated) s += "  return 0;\n";
  s += "}\n";
  return s;
}

std::string op_counts(const EmittedModel& m) {
  std::string s;
  for (const auto& f : m.functions) {
    if (f.name == "jacobian") continue;  // its cost is that of its passes (see its comment)
    s += fmt::format("//   {:<12} {:>7} ({} add, {} mul, {} div, {} func)", f.name, f.ops.total(), f.ops.add, f.ops.mul,
                     f.ops.div, f.ops.func);
    if (f.name == "udot")
      s += fmt::format(" -- {} form; composite {}, articulated {}", m.udot_form, m.udot_composite_ops.total(),
                       m.udot_articulated_ops.total());
    if (!f.kernels.empty())
      s += fmt::format("; compact code: {} kernels ({} operations of code), {} calls, workspace {} ({} values)",
                       f.kernels.size(), f.kernel_ops.total(), f.kernel_calls, f.workspace, f.workspace_values);
    if (!f.ops_by_pass.empty()) {
      std::vector<std::string> parts;
      for (const auto& [pass, n] : f.ops_by_pass) parts.push_back(fmt::format("{} {}", pass, n));
      s += fmt::format("\n//     {} by pass: {}", f.name, join(parts, "; "));
    }
    s += "\n";
  }
  return s;
}

}  // namespace

std::string api_symbol(const EmittedModel& m) { return "kanegen_api_" + m.identifier; }

AssembledFiles assemble(const EmittedModel& m, const std::string& template_dir, const std::string& header_name) {
  AssembledFiles out;
  // ---- header
  std::string functions;
  for (const auto& f : m.functions) functions += function_text(f);
  std::string h = read_template(template_dir + "/model.hpp.in");
  replace_all(h, "GENERATOR_VERSION", KANEGEN_VERSION);
  replace_all(h, "MODEL_DESCRIPTION", m.description.empty() ? "" : " -- " + m.description);
  replace_all(h, "MODEL_NAME_STRING", escaped(m.model_name));
  replace_all(h, "MODEL_NAME", m.model_name);
  replace_all(h, "IDENTIFIER", m.identifier);
  replace_all(h, "MODEL_HASH", m.model_hash);
  replace_all(h, "NQ", std::to_string(m.nq));
  replace_all(h, "NU", std::to_string(m.nu));
  replace_all(h, "NBODIES", std::to_string(m.nbodies));
  replace_all(h, "NW", std::to_string(m.nw));
  replace_all(h, "NY", std::to_string(m.ny));
  {
    std::string pr = fmt::format("inline constexpr int np = {};  // runtime parameters\n", m.np);
    if (m.np > 0) {
      std::vector<std::string> names, units, nominal;
      for (int i = 0; i < m.np; ++i) {
        names.push_back("\"" + escaped(m.parameter_names[i]) + "\"");
        units.push_back("\"" + escaped(m.parameter_units[i]) + "\"");
        nominal.push_back(fmt::format("{:.17g}", m.parameter_nominal[i]));
      }
      pr += "// The runtime parameters: every function but qdot takes their values as prm[np];\n"
            "// parameter_nominal holds the model's values at generation (docs/sweeps.md).\n";
      pr += fmt::format("inline constexpr const char* parameter_names[np] = {{{}}};\n", join(names, ", "));
      pr += fmt::format("inline constexpr const char* parameter_units[np] = {{{}}};\n", join(units, ", "));
      pr += fmt::format("inline constexpr double parameter_nominal[np] = {{{}}};\n", join(nominal, ", "));
    }
    replace_all(h, "PARAMETERS", pr);
  }
  replace_all(h, "IO_NAMES", (m.input_names.empty() ? "" : "// Inputs w:      " + join(m.input_names, ", ") + "\n") +
                                 (m.output_names.empty() ? "" : "// Outputs y:     " + join(m.output_names, ", ") + "\n"));
  replace_all(h, "Q_NAMES", join(m.q_names, ", "));
  replace_all(h, "U_NAMES", join(m.u_names, ", "));
  replace_all(h, "OP_COUNTS", op_counts(m));
  replace_all(h, "CONSTANTS", m.constants);
  const bool joint_sincos =
      std::any_of(m.functions.begin(), m.functions.end(), [](const EmittedFunction& f) { return f.joint_sincos; });
  replace_all(h, "SUPPORT",
              (joint_sincos ? read_template(template_dir + "/joint_sincos.inc") : std::string()) + m.support_code +
                  (m.orbit_frame_rules ? read_template(template_dir + "/orbit_frame.inc") : ""));
  replace_all(h, "FUNCTIONS", functions);
  out.header = std::move(h);

  // ---- entry
  const std::string sym = api_symbol(m);
  std::string any_part, declarations, wrappers, table;
  for (const auto& f : m.functions) {
    const std::string cname = fmt::format("kanegen_{}_{}", m.identifier, f.name);
    any_part += fmt::format(" && !defined(KANEGEN_PART_{})", f.name);
    declarations += fmt::format("int {}(const KanegenArgs* a, double* out);\n", cname);
    const std::string call = fmt::format("ns::{}{}({})", f.name, f.templated ? "<double>" : "", call_arguments(f));
    wrappers += fmt::format("#if defined(KANEGEN_WHOLE) || defined(KANEGEN_PART_{})\n", f.name);
    // the templated functions are inlined into their wrapper, which is
    // compiled once per instruction set (KANEGEN_DISPATCH, model.hpp.in)
    const std::string attrs = f.templated ? "KANEGEN_DISPATCH __attribute__((flatten)) " : "";
    if (f.returns_status)
      wrappers += fmt::format("{}int {}(const KanegenArgs* a, double* out) {{ return {}; }}\n", attrs, cname, call);
    else
      wrappers += fmt::format("{}int {}(const KanegenArgs* a, double* out) {{\n  {};\n  return 0;\n}}\n", attrs,
                              cname, call);
    wrappers += "#endif\n";
    table += fmt::format("#ifndef KANEGEN_OMIT_{}\n    {{\"{}\", &{}, {}}},\n#endif\n", f.name, f.name, cname,
                         f.out_size);
  }
  std::string e = read_template(template_dir + "/entry.cpp.in");
  replace_all(e, "GENERATOR_VERSION", KANEGEN_VERSION);
  replace_all(e, "MODEL_NAME_STRING", escaped(m.model_name));
  replace_all(e, "MODEL_NAME", m.model_name);
  replace_all(e, "HEADER_NAME", header_name);
  replace_all(e, "API_SYMBOL", sym);
  replace_all(e, "ANY_PART", any_part);
  replace_all(e, "IDENTIFIER", m.identifier);
  replace_all(e, "DECLARATIONS", declarations);
  replace_all(e, "WRAPPERS", wrappers);
  replace_all(e, "TABLE_ENTRIES", table);
  replace_all(e, "MODEL_HASH", m.model_hash);
  replace_all(e, "GENERATOR_HASH", m.generator_hash);
  replace_all(e, "NQ", std::to_string(m.nq));
  replace_all(e, "NU", std::to_string(m.nu));
  replace_all(e, "NBODIES", std::to_string(m.nbodies));
  replace_all(e, "NW", std::to_string(m.nw));
  replace_all(e, "NY", std::to_string(m.ny));
  replace_all(e, "NP", std::to_string(m.np));
  out.entry = std::move(e);

  // ---- manifest
  nlohmann::ordered_json j;
  j["format"] = 1;
  j["model"] = m.model_name;
  j["identifier"] = m.identifier;
  j["namespace"] = "kanegen_gen::" + m.identifier;
  j["api_symbol"] = sym;
  j["model_hash"] = m.model_hash;
  j["generator_hash"] = m.generator_hash;
  j["generator_version"] = KANEGEN_VERSION;
  j["nq"] = m.nq;
  j["nu"] = m.nu;
  j["nbodies"] = m.nbodies;
  j["nw"] = m.nw;
  j["ny"] = m.ny;
  j["inputs"] = m.input_names;
  j["outputs"] = m.output_names;
  j["np"] = m.np;
  j["parameters"] = m.parameter_names;
  j["udot_form"] = m.udot_form;
  for (const auto& f : m.functions)
    if (f.name == "udot")
      j["udot_code"] = !f.kernels.empty() ? "compact" : !f.parts.empty() ? "straight-line in parts" : "straight-line";
  j["takes_time"] = std::any_of(m.functions.begin(), m.functions.end(), [](const EmittedFunction& f) {
    return std::find(f.args.begin(), f.args.end(), Arg::t) != f.args.end();
  });
  nlohmann::ordered_json fs = nlohmann::ordered_json::array();
  for (const auto& f : m.functions)
    fs.push_back({{"name", f.name}, {"ops", f.ops.total()}, {"out_size", f.out_size}});
  j["functions"] = fs;
  out.manifest = j.dump(1) + "\n";
  return out;
}

}  // namespace kanegen::codegen
