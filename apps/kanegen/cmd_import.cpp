// kanegen import nastran BULK --modes RUN.f06|RUN.pch [--root GRID] [--second-order] -o BODY.modal.yaml:
// a flexible body's modal data file from a NASTRAN SOL 103 run (issue 36; fea/modal_from_nastran.hpp), with
// the checks against NASTRAN's own printout printed: the weight generator's rigid-body mass and the generalized
// masses against the importer's lumped mass, the root still in every mode.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <set>

#include "apps/kanegen/cli_common.hpp"
#include "fea/modal_from_nastran.hpp"
#include "fea/nastran_bulk.hpp"
#include "fea/nastran_f06.hpp"
#include "fea/nastran_punch.hpp"
#include "model/diagnostics.hpp"
#include "model/modal_data.hpp"
#include "model/output_file.hpp"
#include "model/second_order.hpp"

namespace kanegen::cli {

namespace import_command {

struct Options {
  std::string bulk, modes, output;
  int root = 0;
  bool second_order = false;
  bool accept_mismatch = false;
};

/// A punch file by its extension, else by its first line ("$TITLE", "$EIGENVECTOR", ...: punch lines start with '$').
bool is_punch(const std::string& path) {
  std::string ext = path.substr(path.find_last_of('.') == std::string::npos ? path.size() : path.find_last_of('.'));
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".pch" || ext == ".punch") return true;
  if (ext == ".f06") return false;
  std::ifstream in(path);
  for (std::string s; std::getline(in, s);)
    if (s.find_first_not_of(" \t\r") != std::string::npos) return s[0] == '$';
  return false;
}

int run(const Options& o) {
  using namespace nastran;
  const Bulk bulk = read_bulk(o.bulk);
  std::set<std::string> inputs = {o.bulk, o.modes};
  for (const auto& [id, g] : bulk.grids) inputs.insert(g.file);
  check_output_options({{"-o", o.output}}, {inputs.begin(), inputs.end()});
  const bool punch = is_punch(o.modes);
  const std::vector<Mode> modes = punch ? read_punch_modes(o.modes) : read_f06_modes(o.modes);
  const std::optional<F06Weight> weight = punch ? std::nullopt : read_f06_weight(o.modes);
  ModalImport im = import_modal_data(bulk, o.bulk, modes, o.modes, weight, ModalImportOptions{o.root, o.accept_mismatch});
  FlexibleData& f = im.flex;
  if (o.second_order) {
    try {
      compute_chain_second_order(f);
    } catch (const std::invalid_argument& e) {
      throw InputError(Diagnostic{o.bulk, 0, "--second-order", e.what()});
    }
  }
  write_modal_file(f, o.output);

  fmt::print("{}: {} nodes, {} modes from NASTRAN ({}, {}); origin at root grid {}, axes NASTRAN's basic axes\n",
             o.output, f.nodes.size(), f.modes(), o.bulk, o.modes, im.root);
  fmt::print("  mass {:.7g} (lumped: NASTRAN's default lumped formulation{})\n", im.total_mass,
             bulk.wtmass != 1.0 ? fmt::format(", times WTMASS {:g}", bulk.wtmass) : "");
  if (im.printed_weight) {
    const nastran::WeightSummary &p = *im.printed_weight, &l = *im.lumped_weight;
    fmt::print("  weight generator (input units, basic frame; the lumped mass against NASTRAN's):\n");
    fmt::print("    mass {:.7g} against {:.7g} ({:.1e})\n", l.mass, p.mass, im.mass_error);
    fmt::print("    centre of mass [{:.7g}, {:.7g}, {:.7g}] against [{:.7g}, {:.7g}, {:.7g}] ({:.1e} of the radius of "
               "gyration)\n",
               l.cg.x(), l.cg.y(), l.cg.z(), p.cg.x(), p.cg.y(), p.cg.z(), im.cg_error);
    fmt::print("    inertia about it, diagonal [{:.7g}, {:.7g}, {:.7g}] against [{:.7g}, {:.7g}, {:.7g}] ({:.1e})\n",
               l.inertia_cg(0, 0), l.inertia_cg(1, 1), l.inertia_cg(2, 2), p.inertia_cg(0, 0), p.inertia_cg(1, 1),
               p.inertia_cg(2, 2), im.inertia_error);
    fmt::print("    MO about its reference point: {:.1e} of its largest entry\n", *im.weight_generator_error);
  } else {
    fmt::print("  weight generator: no check of the total mass against NASTRAN: {}\n",
               punch ? "a punch file prints none" : im.weight_generator_note);
  }
  if (!im.generalized_masses.empty()) {
    const auto worst = std::max_element(im.generalized_masses.begin(), im.generalized_masses.end(),
                                        [](const auto& a, const auto& b) { return a.relative_error() < b.relative_error(); });
    fmt::print("  generalized masses: phi^T M phi with the lumped mass equals NASTRAN's to {:.1e} (worst: mode {})\n",
               worst->relative_error(), worst->mode);
  } else {
    fmt::print("  generalized masses: {}; the shapes are normalized with the lumped mass\n",
               punch ? "a punch file prints none" : "none printed");
  }
  fmt::print("  root grid {}: still in every mode (largest motion {:.1e} of a mode's largest entry)\n", im.root,
             im.root_motion);
  if (o.second_order) fmt::print("  second_order computed from the shapes along the chain of nodes\n");
  for (int j = 0; j < f.modes(); ++j) fmt::print("  mode {} (NASTRAN's {}): {:.7g} Hz\n", j + 1, im.modes[j], f.frequency_hz(j));
  for (const std::string& n : im.notes) fmt::print("  note: {}\n", n);
  for (const std::string& w : im.mismatches)
    fmt::print(stderr, "warning: the lumped mass is not NASTRAN's (--accept-mass-mismatch): {}\n", w);
  return 0;
}

}  // namespace import_command

Subcommand add_import(CLI::App& app) {
  auto o = std::make_shared<import_command::Options>();
  CLI::App* group = app.add_subcommand("import", "write a flexible body's modal data file from an FEA run");
  group->require_subcommand(1);
  CLI::App* c = group->add_subcommand(
      "nastran",
      "a NASTRAN SOL 103 run: the bulk data (GRID, CBAR, CBEAM, CROD, CONROD, CONM2 and their properties) and its "
      "modes (f06 or punch) -> a *.modal.yaml with origin at the clamped root grid, NASTRAN's basic axes, the lumped "
      "node masses and unit-modal-mass shapes; prints the checks against NASTRAN's weight generator and generalized "
      "masses");
  c->add_option("bulk", o->bulk, "the bulk data file (or the whole input file; INCLUDEs are followed)")
      ->required()
      ->check(CLI::ExistingFile);
  c->add_option("--modes", o->modes, "the run's .f06 (eigenvalue table, eigenvectors) or punch file (.pch)")
      ->required()
      ->check(CLI::ExistingFile);
  c->add_option("--root", o->root,
                "the grid at the body's origin, clamped in the run (default: the single grid with SPC 123456)");
  c->add_flag("--second-order", o->second_order,
              "also write second_order (foreshortening) data, computed from the shapes where the nodes form a chain "
              "from the root");
  c->add_flag("--accept-mass-mismatch", o->accept_mismatch,
              "write the data even when the lumped mass differs from NASTRAN's printout beyond 1e-4 (warned); "
              "without it such a run is refused with the figures");
  c->add_option("-o,--output", o->output, "output *.modal.yaml")->required();
  return {c, [o] { return import_command::run(*o); }};
}

}  // namespace kanegen::cli
