// The modal importer (fea/modal_from_nastran, fea/nastran_punch; issue 36) on
// the shared Simcenter Nastran SOL 103 run: the punch layout read to the same
// modes as the f06; the modal file's mass proved against NASTRAN's printout
// (generalized masses, weight generator) and, through a model that loads the
// written file, the whole body's mass, centre of mass and inertia against the
// weight generator's; the clamped model's linear frequencies against
// NASTRAN's; refusals by file and reason.
#include <catch2/catch.hpp>

#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "fea/modal_from_nastran.hpp"
#include "fea/nastran_bulk.hpp"
#include "fea/nastran_f06.hpp"
#include "fea/nastran_punch.hpp"
#include "model/diagnostics.hpp"
#include "model/modal_data.hpp"
#include "sim/linearize.hpp"
#include "sim/mass_properties.hpp"
#include "tests/support/shell.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;
using namespace kanegen::nastran;
namespace fs = std::filesystem;

namespace {

using test::shared_run;

ModalImport import_f06() {
  const std::string f06 = shared_run("beam_modes.f06");
  return import_modal_data(read_bulk(shared_run("beam_modes.dat")), shared_run("beam_modes.dat"), read_f06_modes(f06),
                           f06, read_f06_weight(f06));
}

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

}  // namespace

TEST_CASE("nastran punch: the eigenvectors of the shared run in the punch layout read as from its f06",
          "[nastran]") {
  const std::vector<Mode> f06 = read_f06_modes(shared_run("beam_modes.f06"));
  const std::vector<Mode> pch = read_punch_modes(shared_run("beam_modes_eigenvectors.pch"));
  REQUIRE(pch.size() == f06.size());
  for (std::size_t j = 0; j < pch.size(); ++j) {
    INFO(fmt::format("mode {}", f06[j].number));
    CHECK(pch[j].number == f06[j].number);
    CHECK(pch[j].eigenvalue == f06[j].eigenvalue);
    CHECK(pch[j].generalized_mass == 0.0);  // a punch file prints none
    // cycles from the eigenvalue: as the f06 prints them, to its 7 digits
    CHECK(std::abs(pch[j].cycles - f06[j].cycles) <= 1e-6 * f06[j].cycles);
    REQUIRE(pch[j].shapes.size() == 12);
    for (const auto& [grid, v] : f06[j].shapes) CHECK(pch[j].shapes.at(grid) == v);
  }
}

TEST_CASE("nastran punch: complex eigenvectors and files without eigenvectors are refused by file and line",
          "[nastran][refusal]") {
  const fs::path d = test::scratch_dir("nastran", "punch");
  write_text(d / "complex.pch",
             "$TITLE   = X\n$SUBTITLE=\n$LABEL   =\n$EIGENVECTOR\n$REAL-IMAGINARY OUTPUT\n$SUBCASE ID =           1\n"
             "$EIGENVALUE =  1.0000000E+02  MODE =     1\n         1       G      1.0E+00      0.0      0.0\n");
  try {
    read_punch_modes((d / "complex.pch").string());
    FAIL("a complex eigenvector block was accepted");
  } catch (const InputError& e) {
    const std::string what = e.diagnostics().front().str();
    CHECK(what.find("complex.pch:7") != std::string::npos);
    CHECK(what.find("complex") != std::string::npos);
  }
  write_text(d / "displacements.pch",
             "$TITLE   = X\n$DISPLACEMENTS\n$REAL OUTPUT\n$SUBCASE ID =           1\n"
             "         1       G      1.0E+00      0.0      0.0\n-CONT-                  0.0      0.0      0.0\n");
  CHECK_THROWS_AS(read_punch_modes((d / "displacements.pch").string()), InputError);
  // a grid row without its -CONT- row (R1 R2 R3), and a mode punched twice (two subcases): refused at the line
  write_text(d / "short.pch",
             "$TITLE   = X\n$EIGENVECTOR\n$REAL OUTPUT\n$EIGENVALUE =  1.0000000E+02  MODE =     1\n"
             "         1       G      1.0E+00      0.0      0.0\n         2       G      1.0E+00      0.0      0.0\n");
  try {
    read_punch_modes((d / "short.pch").string());
    FAIL("a grid row without its rotations was accepted");
  } catch (const InputError& e) {
    CHECK(e.diagnostics().front().str().find("short.pch:6") != std::string::npos);
    CHECK(e.diagnostics().front().str().find("grid 1: its -CONT- row") != std::string::npos);
  }
  write_text(d / "twice.pch",
             "$TITLE   = X\n$EIGENVECTOR\n$REAL OUTPUT\n$SUBCASE ID =  1\n$EIGENVALUE =  1.0000000E+02  MODE =     1\n"
             "         1       G      1.0E+00      0.0      0.0\n-CONT-        0.0     0.0     0.0\n"
             "$TITLE   = X\n$EIGENVECTOR\n$REAL OUTPUT\n$SUBCASE ID =  2\n$EIGENVALUE =  2.0000000E+02  MODE =     1\n");
  CHECK_THROWS_AS(read_punch_modes((d / "twice.pch").string()), InputError);
  fs::remove_all(d);
}

TEST_CASE("nastran import: the shared run's modal data, its mass proved against NASTRAN's weight generator and "
          "generalized masses",
          "[nastran][physics]") {
  const ModalImport im = import_f06();
  const FlexibleData& f = im.flex;
  CHECK(im.root == 1);  // SPC 1 123456 at grid 1
  // grids 1..11 on the x axis from the root; grid 12 (no mass, no element, AUTOSPC'd) dropped with a note
  REQUIRE(f.nodes.size() == 11);
  for (int k = 0; k < 11; ++k) {
    CHECK(f.nodes[k].id == k + 1);
    CHECK((f.nodes[k].rho_B - Vec3(k, 0, 0)).norm() == 0.0);
  }
  REQUIRE(!im.notes.empty());
  CHECK(im.notes.front().find("12") != std::string::npos);
  CHECK(f.modes() == 10);
  // the weight generator's mass 2.610514E-02 (SOURCE.md), and its MO, to its printed digits
  CHECK(std::abs(im.total_mass - 2.610514e-2) <= 1e-6 * 2.610514e-2);
  REQUIRE(im.weight_generator_error);
  CHECK(*im.weight_generator_error < 1e-6);
  // every printed generalized mass reproduced as phi^T M phi with the mass written to the file
  REQUIRE(im.generalized_masses.size() == 10);
  for (const GeneralizedMassCheck& g : im.generalized_masses) {
    INFO(fmt::format("mode {}: printed {}, computed {}", g.mode, g.printed, g.computed));
    CHECK(g.relative_error() < 1e-6);
  }
  CHECK(im.root_motion == 0.0);
  // the weight generator's mass, centre of mass and inertia read from its MO, against the lumped mass's
  REQUIRE(im.printed_weight);
  CHECK(std::abs(im.printed_weight->mass - 2.610514e-2) <= 1e-6 * 2.610514e-2);
  CHECK(std::abs(im.printed_weight->cg.x() - 5.496071) <= 1e-6 * 5.496071);
  CHECK(im.mass_error < 1e-6);
  CHECK(im.cg_error < 1e-6);
  CHECK(im.inertia_error < 1e-6);
  CHECK(im.mismatches.empty());
  // unit modal mass (the contract's formula), frequencies as NASTRAN's cycles
  const VecX Y = modal_masses(f);
  for (int j = 0; j < f.modes(); ++j) CHECK(std::abs(Y(j) - 1.0) < 1e-12);
  CHECK(f.frequency_hz(4) == 3.554923e3);
  // the unique modes at the tip (grid 11, node index 10): NASTRAN's MAX-normalized vector over sqrt(its printed
  // generalized mass): torsion (mode 5) is R1, the axial mode (6) T1
  CHECK(std::abs(f.Psi(30, 4) - 1.0 / std::sqrt(3.668128e-3)) <= 1e-6 / std::sqrt(3.668128e-3));
  CHECK(std::abs(f.Phi(30, 5) - 1.0 / std::sqrt(1.334596e-2)) <= 1e-6 / std::sqrt(1.334596e-2));
  // the pairs are noted as degenerate
  int pairs = 0;
  for (const std::string& n : im.notes) pairs += n.find("one frequency") != std::string::npos;
  CHECK(pairs == 4);
}

TEST_CASE("nastran import: the punch file gives the modal data the f06 gives", "[nastran]") {
  const ModalImport a = import_f06();
  const std::string pch = shared_run("beam_modes_eigenvectors.pch");
  const ModalImport b = import_modal_data(read_bulk(shared_run("beam_modes.dat")), shared_run("beam_modes.dat"),
                                          read_punch_modes(pch), pch, std::nullopt);
  REQUIRE(b.flex.nodes.size() == a.flex.nodes.size());
  CHECK(b.generalized_masses.empty());
  CHECK(!b.weight_generator_error);
  CHECK(test::rel_err(b.flex.Phi, a.flex.Phi) < 1e-14);
  CHECK(test::rel_err(b.flex.Psi, a.flex.Psi) < 1e-14);
  CHECK(test::rel_err(b.flex.frequency_hz, a.flex.frequency_hz) < 1e-6);
}

TEST_CASE("nastran import: the written file, loaded in a model, has the weight generator's mass, centre of mass "
          "and inertia, and the clamped model's linear frequencies are NASTRAN's",
          "[nastran][physics]") {
  const fs::path d = test::scratch_dir("nastran", "model");
  ModalImport im = import_f06();
  write_modal_file(im.flex, (d / "rod.modal.yaml").string());
  std::vector<Diagnostic> ds;
  const FlexibleData back = load_modal_file((d / "rod.modal.yaml").string(), {}, ds);
  REQUIRE(ds.empty());
  CHECK(test::rel_err(back.Phi, im.flex.Phi) == 0.0);

  // free: the body's mass properties at rest (the loader's modal integrals, not the importer's lumping)
  write_text(d / "free.yaml",
             "name: rod_free\ngravity: [0, 0, 0]\nbodies:\n  - name: rod\n    parent: ground\n"
             "    joint: {type: free}\n    flexible: {modal: rod.modal.yaml}\n");
  const Model free = load_model((d / "free.yaml").string());
  const SystemMassProperties p = system_mass_properties(free, initial_state(free));
  // GPWG (SOURCE.md): mass 2.610514E-02, C.G. (5.496071, 0, 0), I(S) diag(3.765757E-03, 2.607945E-01, 2.607945E-01)
  CHECK(std::abs(p.mass - 2.610514e-2) <= 1e-6 * 2.610514e-2);
  CHECK(std::abs(p.com_N.x() - 5.496071) <= 1e-6 * 5.496071);
  CHECK(p.com_N.tail<2>().norm() == 0.0);
  const Vec3 I(3.765757e-3, 2.607945e-1, 2.607945e-1);
  for (int a = 0; a < 3; ++a) CHECK(std::abs(p.J_com_N(a, a) - I(a)) <= 1e-6 * I(a));
  CHECK(std::abs(p.J_com_N(0, 1)) + std::abs(p.J_com_N(0, 2)) + std::abs(p.J_com_N(1, 2)) <= 1e-12);

  // clamped: the linear model's frequencies are the run's eigenvalues
  write_text(d / "clamped.yaml",
             "name: rod_clamped\ngravity: [0, 0, 0]\nbodies:\n  - name: rod\n    parent: ground\n"
             "    joint: {type: fixed}\n    flexible: {modal: rod.modal.yaml}\n");
  const Model clamped = load_model((d / "clamped.yaml").string());
  GenericEngine engine(clamped);
  const std::vector<LinearMode> modes = linear_modes(linearize(engine, initial_state(clamped), {}));
  const std::vector<Mode> nastran = read_f06_modes(shared_run("beam_modes.f06"));
  REQUIRE(modes.size() == nastran.size());
  for (std::size_t j = 0; j < modes.size(); ++j) {
    const double omega = std::sqrt(nastran[j].eigenvalue);  // rad/s, from the printed eigenvalue
    INFO(fmt::format("mode {}: {} rad/s, NASTRAN {}", j + 1, std::abs(modes[j].eigenvalue), omega));
    CHECK(std::abs(std::abs(modes[j].eigenvalue) - omega) <= 1e-6 * omega);
  }
  fs::remove_all(d);
}

TEST_CASE("nastran import: a root that moves, or no clamped grid, is refused naming the file and the root",
          "[nastran][refusal]") {
  const std::string dat = shared_run("beam_modes.dat"), f06 = shared_run("beam_modes.f06");
  const Bulk bulk = read_bulk(dat);
  const std::vector<Mode> modes = read_f06_modes(f06);
  try {
    import_modal_data(bulk, dat, modes, f06, std::nullopt, ModalImportOptions{11});
    FAIL("grid 11, the tip, was accepted as the clamped root");
  } catch (const InputError& e) {
    const std::string what = e.diagnostics().front().str();
    CHECK(what.find("beam_modes.f06") != std::string::npos);
    CHECK(what.find("root grid 11 moves") != std::string::npos);
  }
  CHECK_THROWS_AS(import_modal_data(bulk, dat, modes, f06, std::nullopt, ModalImportOptions{99}), InputError);
  Bulk unclamped = bulk;
  for (auto& [id, g] : unclamped.grids) g.spc.clear();
  try {
    import_modal_data(unclamped, dat, modes, f06, std::nullopt);
    FAIL("a run without a clamped grid was accepted without --root");
  } catch (const InputError& e) {
    CHECK(e.diagnostics().front().field == "--root");
  }
}

TEST_CASE("nastran import: an offset CONM2's mass moves to a node of its own, with the grid's 6 x 6 lumped mass "
          "matrix's generalized masses",
          "[nastran][physics]") {
  const std::string dat = shared_run("beam_modes.dat"), f06 = shared_run("beam_modes.f06");
  Bulk bulk = read_bulk(dat);
  REQUIRE(bulk.masses.size() == 1);
  bulk.masses[0].offset_basic = Vec3(0.2, 0.3, -0.4);  // the tip mass off grid 11
  const std::vector<Mode> modes = read_f06_modes(f06);
  // the f06's generalized masses are of the run without the offset: accepted only when asked, and said
  CHECK_THROWS_AS(import_modal_data(bulk, dat, modes, f06, std::nullopt), InputError);
  const ModalImport im = import_modal_data(bulk, dat, modes, f06, std::nullopt, ModalImportOptions{0, true});
  CHECK(!im.mismatches.empty());
  const FlexibleData& f = im.flex;
  REQUIRE(f.nodes.size() == 12);
  const ModalNode& grid11 = f.nodes[10];
  const ModalNode& centre = f.nodes[11];
  CHECK(grid11.id == 11);
  CHECK(centre.id == 13);  // the first id after the deck's grids
  CHECK(grid11.mass == 0.0);
  // the grid's whole mass (its elements' half and the CONM2) at their common centre
  const auto lumped = lumped_masses(bulk);
  const GridMass& g = lumped.at(11);
  CHECK(std::abs(centre.mass - g.mass) <= 1e-15);
  const Vec3 d = centre.rho_B - grid11.rho_B;
  CHECK((g.mass * d - 2.59e-3 * Vec3(0.2, 0.3, -0.4)).norm() <= 1e-15);
  // phi^T M phi with the grid's 6 x 6 lumped mass (coupling included), NASTRAN's normalization, against the
  // generalized masses of the import (the split nodes' contract formula)
  for (const GeneralizedMassCheck& c : im.generalized_masses) {
    const Mode& m = modes[c.mode - 1];
    double gm = 0.0;
    for (const auto& [id, gmass] : lumped) {
      const Eigen::Matrix<double, 6, 1> v = m.shapes.at(id);
      Eigen::Matrix<double, 6, 6> M6 = Eigen::Matrix<double, 6, 6>::Zero();
      M6.topLeftCorner<3, 3>() = gmass.mass * Mat3::Identity();
      M6.topRightCorner<3, 3>() = gmass.coupling;
      M6.bottomLeftCorner<3, 3>() = gmass.coupling.transpose();
      M6.bottomRightCorner<3, 3>() = gmass.inertia;
      gm += v.dot(M6 * v);
    }
    INFO(fmt::format("mode {}", c.mode));
    CHECK(std::abs(c.computed - gm) <= 1e-12 * gm);
  }
  // the grid's rotary inertia about the centre is positive semi-definite
  CHECK(Eigen::SelfAdjointEigenSolver<Mat3>(centre.J_B).eigenvalues().minCoeff() >= -1e-15);
}

TEST_CASE("cli: kanegen import nastran writes the modal file and prints its checks, a bad deck is refused with "
          "file and line, nothing written",
          "[nastran][cli]") {
  const fs::path d = test::scratch_dir("nastran", "cli");
  for (const char* f : {"beam_modes.dat", "cbar_cbeam.blk", "beam_modes.f06", "beam_modes_eigenvectors.pch"})
    fs::copy_file(shared_run(f), d / f);
  const test::ShellRun help = test::run_kanegen("import nastran --help");
  CHECK(help.status == 0);
  for (const char* option : {"--modes", "--root", "--second-order", "-o"}) CHECK(help.out.find(option) != std::string::npos);

  const test::ShellRun ok = test::run_kanegen("import nastran beam_modes.dat --modes beam_modes.f06 -o rod.modal.yaml",
                                              d.string());
  INFO(ok.out);
  REQUIRE(ok.status == 0);
  CHECK(ok.out.find("11 nodes, 10 modes") != std::string::npos);
  CHECK(ok.out.find("generalized masses: phi^T M phi with the lumped mass equals NASTRAN's to") != std::string::npos);
  CHECK(ok.out.find("warning") == std::string::npos);
  std::vector<Diagnostic> ds;
  const FlexibleData f = load_modal_file((d / "rod.modal.yaml").string(), {}, ds);
  CHECK(ds.empty());
  CHECK(f.modes() == 10);

  // the punch file, with --second-order along the rod's chain of nodes
  const test::ShellRun pch = test::run_kanegen(
      "import nastran beam_modes.dat --modes beam_modes_eigenvectors.pch --second-order -o rod2.modal.yaml", d.string());
  INFO(pch.out);
  REQUIRE(pch.status == 0);
  const FlexibleData g = load_modal_file((d / "rod2.modal.yaml").string(), {}, ds);
  CHECK(ds.empty());
  CHECK(g.has_second_order(10));

  // the imported rod on a bus (docs/from_nastran.md's example): checks and simulates
  fs::copy_file(test::source_path("tests/data/fea/rod_on_bus.yaml"), d / "rod_on_bus.yaml");
  const test::ShellRun check = test::run_kanegen("check rod_on_bus.yaml", d.string());
  INFO(check.out);
  CHECK(check.status == 0);
  const test::ShellRun sim = test::run_kanegen(
      "simulate rod_on_bus.yaml --engine generic --t-end 0.01 --dt-out 0.001 --no-progress -o rod.csv", d.string());
  INFO(sim.out);
  CHECK(sim.status == 0);
  CHECK(fs::exists(d / "rod.csv"));
  // a plate in the deck: refused at its line, nothing written
  {
    std::ofstream(d / "cbar_cbeam.blk", std::ios::app) << "CQUAD4  100     1       1       2       3       4\n";
  }
  const test::ShellRun bad = test::run_kanegen("import nastran beam_modes.dat --modes beam_modes.f06 -o bad.modal.yaml",
                                               d.string());
  INFO(bad.out);
  CHECK(bad.status == 2);
  CHECK(bad.out.find("cbar_cbeam.blk:") != std::string::npos);
  CHECK(bad.out.find("CQUAD4") != std::string::npos);
  CHECK(!fs::exists(d / "bad.modal.yaml"));
  // the output on an input: refused
  const test::ShellRun onto = test::run_kanegen("import nastran beam_modes.dat --modes beam_modes.f06 -o beam_modes.f06",
                                                d.string());
  CHECK(onto.status == 2);
  fs::remove_all(d);
}

TEST_CASE("nastran import: a lumped mass that is not NASTRAN's is refused with the figures unless accepted, a run "
          "without eigenvectors is refused",
          "[nastran][refusal]") {
  const std::string dat = shared_run("beam_modes.dat"), f06 = shared_run("beam_modes.f06");
  Bulk bulk = read_bulk(dat);
  bulk.masses[0].mass *= 2.0;  // the tip mass doubled: not the run's structure
  const std::vector<Mode> modes = read_f06_modes(f06);
  const std::optional<F06Weight> weight = read_f06_weight(f06);
  try {
    import_modal_data(bulk, dat, modes, f06, weight);
    FAIL("a lumped mass 10 % off NASTRAN's was accepted");
  } catch (const InputError& e) {
    const std::string what = e.diagnostics().front().str();
    INFO(what);
    CHECK(what.find("beam_modes.f06") != std::string::npos);
    CHECK(what.find("mass 0.02869514 against the weight generator's 0.02610514") != std::string::npos);
    CHECK(what.find("mode 1: generalized mass") != std::string::npos);
    CHECK(what.find("--accept-mass-mismatch") != std::string::npos);
  }
  const ModalImport accepted = import_modal_data(bulk, dat, modes, f06, weight, ModalImportOptions{0, true});
  CHECK(accepted.mismatches.size() >= 3);
  CHECK(std::abs(accepted.mass_error - 2.59e-3 / 2.610514e-2) < 1e-6);
  // modes without eigenvectors: nothing to import
  std::vector<Mode> bare = modes;
  for (Mode& m : bare) m.shapes.clear();
  try {
    import_modal_data(read_bulk(dat), dat, bare, f06, weight);
    FAIL("modes without eigenvectors were accepted");
  } catch (const InputError& e) {
    CHECK(e.diagnostics().front().str().find("no mode has an eigenvector") != std::string::npos);
  }
}
