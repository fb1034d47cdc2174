#include "generate.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "kane_builder.hpp"
#include "merge_fixed.hpp"
#include "model_hash.hpp"

namespace kanegen::gen {

namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path);
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

constexpr const char* kIndent = "  ";

struct FunctionBody {
  std::string code;
  OpCount ops;
};

FunctionBody finish(const Program& p) {
  FunctionBody f;
  f.code = p.emit(kIndent, f.ops);
  return f;
}

std::string body_comment(const Model& model, const Body& b) {
  const std::string parent = b.parent < 0 ? "ground" : model.bodies[b.parent].name;
  std::string s = fmt::format("// body {}: {} joint to {}", b.name, to_string(b.joint.type), parent);
  if (b.joint.node >= 0) s += fmt::format(" at node {}", model.bodies[b.parent].flex->nodes[b.joint.node].id);
  s += fmt::format(", mass {:.6g} kg", b.integrals.mass);
  // the file name only: the bytes must not depend on where the model was read from
  if (b.flex)
    s += fmt::format(", flexible: {} modes from {}", b.n_modes(), std::filesystem::path(b.flex->source).filename().string());
  return s + "\n";
}

}  // namespace

GeneratedCode generate(const Model& model_in, const GeneratorOptions& options) {
  if (options.udot_form != "auto" && options.udot_form != "composite" && options.udot_form != "articulated")
    throw std::invalid_argument("udot form must be auto, composite or articulated");
  const Model merged = options.merge_fixed ? merge_fixed_bodies(model_in) : model_in;
  const Model& dyn = merged;  // used for M, F, u_dot, energy, momentum
  Constants C;
  const StateSymbols x(dyn);
  GeneratedCode out;
  std::map<std::string, FunctionBody> fn;

  {  // q_dot
    Program p;
    KaneBuilder kb(dyn, p, C, x);
    const auto qd = kb.qdot();
    for (int i = 0; i < dyn.nq; ++i) p.assign(fmt::format("qdot[{}]", i), qd[i]);
    fn["qdot"] = finish(p);
  }
  {  // M
    Program p;
    KaneBuilder kb(dyn, p, C, x);
    kb.prepare(false);
    const SMat M = kb.mass_matrix();
    for (int r = 0; r < dyn.nu; ++r)
      for (int c = 0; c < dyn.nu; ++c) p.assign(fmt::format("M[{}]", r * dyn.nu + c), M(r, c));
    fn["mass_matrix"] = finish(p);
  }
  {  // F
    Program p;
    KaneBuilder kb(dyn, p, C, x);
    kb.prepare(true);
    const auto F = kb.forcing();
    for (int r = 0; r < dyn.nu; ++r) p.assign(fmt::format("F[{}]", r), F[r]);
    fn["forcing"] = finish(p);
  }
  // u_dot: the composite-inertia form (M by composite inertias, F by the
  // inward pass, L^T D L along the tree; O(n^2) plus O(n d^2)) or the
  // articulated-body form (O(n)), whichever takes fewer operations here.
  for (const char* form : {"composite", "articulated"}) {
    Program p;
    KaneBuilder kb(dyn, p, C, x);
    kb.prepare(true);
    std::vector<ex> pivots, ud;
    if (std::string(form) == "composite") {
      const SMat M = kb.mass_matrix();
      const auto F = kb.forcing();
      ud = kb.solve(M, F, pivots);
    } else {
      ud = kb.udot_articulated(pivots);
    }
    OpCount dummy;
    for (std::size_t k = 0; k < pivots.size(); ++k)
      p.statement(fmt::format("if (!({} > 0.0)) return {};", print_cpp(pivots[k], dummy), k + 1), pivots[k]);
    for (int r = 0; r < dyn.nu; ++r) p.assign(fmt::format("udot[{}]", r), ud[r]);
    FunctionBody f = finish(p);
    out.ops[std::string("udot_") + form] = f.ops;
    const bool forced = options.udot_form == form;
    const bool chosen_forced = options.udot_form != "auto" && fn.count("udot");
    if (forced || (!chosen_forced && (!fn.count("udot") || f.ops.total() < fn["udot"].ops.total()))) {
      fn["udot"] = std::move(f);
      out.udot_form = form;
    }
  }
  std::string optional;
  std::string macros;
  // An optional output function: its section comment, signature and the
  // macro that tells templates/entry.cpp.in it exists.
  auto add_optional = [&](const std::string& name, const std::string& title, const std::string& signature,
                          const std::string& unused, const std::string& macro) {
    optional += "\n// ---- " + title + "\ntemplate <class T>\nvoid " + name + "(" + signature +
                ") {\n  using std::cos; using std::sin; using std::sqrt;\n  " + unused + "\n" + fn[name].code + "}\n";
    macros += "#define " + macro + " 1\n";
  };
  const auto& outs = model_in.outputs;
  if (outs.energy) {
    Program p;
    KaneBuilder kb(dyn, p, C, x);
    kb.prepare(true);
    p.assign("TV[0]", kb.kinetic_energy());
    p.assign("TV[1]", kb.potential_energy());
    fn["energy"] = finish(p);
    add_optional("energy", "energy: T, V -----------------------------------------------------------------",
                 "const T* q, const T* u, T* TV", "(void)q; (void)u;", "KANEGEN_HAS_ENERGY");
  }
  if (outs.momentum) {
    Program p;
    KaneBuilder kb(dyn, p, C, x);
    kb.prepare(true);
    const auto pH = kb.momentum();
    for (int i = 0; i < 6; ++i) p.assign(fmt::format("pH[{}]", i), pH[i]);
    fn["momentum"] = finish(p);
    add_optional("momentum", "momentum: p_N[3], H_N[3] about N's origin ------------------------------------",
                 "const T* q, const T* u, T* pH", "(void)q; (void)u;", "KANEGEN_HAS_MOMENTUM");
  }
  if (outs.reactions) {  // on the unmerged tree: every body, fixed ones included
    const StateSymbols xr(model_in);
    Program p;
    KaneBuilder kb(model_in, p, C, xr);
    kb.prepare(true);
    const auto W = kb.reactions(xr.udot);
    for (std::size_t i = 0; i < W.size(); ++i) p.assign(fmt::format("wrenches[{}]", i), W[i]);
    fn["reactions"] = finish(p);
    add_optional("reactions", "reactions on each body from its parent: [force; torque about O_B], body axes --",
                 "const T* q, const T* u, const T* udot_in, T* wrenches", "(void)q; (void)u; (void)udot_in;",
                 "KANEGEN_HAS_REACTIONS");
  }

  // Constants, grouped per body with a comment block.
  std::string constants;
  for (const std::string& g : C.groups()) {
    const int bi = model_in.body_index(g);
    if (bi >= 0)
      constants += body_comment(model_in, model_in.bodies[bi]);
    else
      constants += "// model\n";
    constants += C.emit(g, "") + "\n";
  }

  std::string op_counts;
  for (const auto& [name, f] : fn) {
    out.ops[name] = f.ops;
    if (name == "udot") {
      op_counts += fmt::format("//   {:<12} {:>7} ({} add, {} mul, {} div, {} func) -- {} form; composite {}, articulated {}\n",
                               name, f.ops.total(), f.ops.add, f.ops.mul, f.ops.div, f.ops.func, out.udot_form,
                               out.ops.at("udot_composite").total(), out.ops.at("udot_articulated").total());
      continue;
    }
    op_counts += fmt::format("//   {:<12} {:>7} ({} add, {} mul, {} div, {} func)\n", name, f.ops.total(), f.ops.add,
                             f.ops.mul, f.ops.div, f.ops.func);
  }

  const std::string tdir =
      options.template_dir.empty() ? std::string(KANEGEN_SOURCE_DIR) + "/templates" : options.template_dir;
  std::string h = read_file(tdir + "/model.hpp.in");
  replace_all(h, "GENERATOR_VERSION", KANEGEN_VERSION);
  replace_all(h, "MODEL_DESCRIPTION", model_in.description.empty() ? "" : " -- " + model_in.description);
  replace_all(h, "MODEL_NAME", model_in.name);
  replace_all(h, "MODEL_HASH", model_hash(model_in));
  replace_all(h, "NQ", std::to_string(model_in.nq));
  replace_all(h, "NU", std::to_string(model_in.nu));
  replace_all(h, "NX", std::to_string(model_in.nq + model_in.nu));
  replace_all(h, "NBODIES", std::to_string(model_in.bodies.size()));
  replace_all(h, "Q_NAMES", join(model_in.q_names, ", "));
  replace_all(h, "U_NAMES", join(model_in.u_names, ", "));
  replace_all(h, "OP_COUNTS", op_counts);
  replace_all(h, "HAS_ENERGY", outs.energy ? "true" : "false");
  replace_all(h, "HAS_MOMENTUM", outs.momentum ? "true" : "false");
  replace_all(h, "HAS_REACTIONS", outs.reactions ? "true" : "false");
  replace_all(h, "OPTIONAL_MACROS", macros);
  replace_all(h, "CONSTANTS", constants);
  replace_all(h, "QDOT_BODY", fn["qdot"].code);
  replace_all(h, "MASS_MATRIX_BODY", fn["mass_matrix"].code);
  replace_all(h, "FORCING_BODY", fn["forcing"].code);
  replace_all(h, "UDOT_BODY", fn["udot"].code);
  replace_all(h, "OPTIONAL_FUNCTIONS", optional);
  // One direction per pass: the code of each pass stays about twice the size of
  // u_dot itself, which keeps compile times low (8 directions per pass compiled
  // 5x slower for a 1.5x faster Jacobian).
  replace_all(h, "DUAL_WIDTH", "1");
  out.header = std::move(h);
  return out;
}

std::string generate_header(const Model& model) { return generate(model).header; }

}  // namespace kanegen::gen
