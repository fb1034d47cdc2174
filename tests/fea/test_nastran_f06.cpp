// The modes of the shared Simcenter Nastran SOL 103 run read from its f06
// (fea/nastran_f06; issue 36): the eigenvalue table, the eigenvectors of all
// 12 grids, and NASTRAN's printed generalized masses reproduced as phi^T M phi
// with the importer's own lumped mass (fea/nastran_bulk) for every mode.
#include <catch2/catch.hpp>

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "fea/nastran_bulk.hpp"
#include "fea/nastran_f06.hpp"
#include "model/diagnostics.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;
using namespace kanegen::nastran;

namespace {

using test::shared_run;

}  // namespace

TEST_CASE("nastran f06: the shared run's modes, and their generalized masses as phi^T M phi with the importer's "
          "lumped mass",
          "[nastran][physics]") {
  const std::vector<Mode> modes = read_f06_modes(shared_run("beam_modes.f06"));
  REQUIRE(modes.size() == 10);
  // the eigenvalue table as printed (SOURCE.md)
  CHECK(modes[0].cycles == 4.566603e2);
  CHECK(modes[4].eigenvalue == 4.989076e8);
  CHECK(modes[9].generalized_mass == 2.216687e-2);
  const Bulk bulk = read_bulk(shared_run("beam_modes.dat"));
  const auto lumped = lumped_masses(bulk);
  for (const Mode& m : modes) {
    INFO(fmt::format("mode {}", m.number));
    REQUIRE(m.shapes.size() == 12);  // every grid, the AUTOSPC'd grid 12 as zeros
    // the printed eigenvalue, radians and cycles agree to their 7 printed digits
    CHECK(std::sqrt(m.eigenvalue) / (2.0 * std::numbers::pi) == Approx(m.cycles).epsilon(1e-6));
    // the clamped root and the unconnected grid 12 do not move
    CHECK(m.shapes.at(1).cwiseAbs().maxCoeff() == 0.0);
    CHECK(m.shapes.at(12).cwiseAbs().maxCoeff() == 0.0);
    double gm = 0.0;
    for (const auto& [id, g] : lumped) {
      const Eigen::Matrix3d& R = bulk.grids.at(id).R_basic_cd;
      const Eigen::Vector3d t = R * m.shapes.at(id).head<3>(), r = R * m.shapes.at(id).tail<3>();
      gm += g.mass * t.squaredNorm() + 2.0 * t.dot(g.coupling * r) + r.dot(g.inertia * r);
    }
    // NASTRAN's generalized mass (MAX normalization, so not 1) from the printed 7-digit eigenvectors
    CHECK(gm == Approx(m.generalized_mass).epsilon(1e-6));
  }
  // the unique modes at the tip, grid 11: torsion (mode 5) R1 = 1, axial (mode 6) T1 = 1
  CHECK(modes[4].shapes.at(11)(3) == 1.0);
  CHECK(modes[5].shapes.at(11)(0) == 1.0);
  CHECK(std::abs(modes[4].shapes.at(11)(0)) < 1e-15);
}

TEST_CASE("nastran f06: a file without real modes is refused with its name", "[nastran]") {
  CHECK_THROWS_WITH(read_f06_modes(test::write_temp("empty.f06", "no modes here\n")),
                    Catch::Contains("empty.f06") && Catch::Contains("no REAL EIGENVALUES table"));
  CHECK_THROWS_WITH(read_f06_modes(test::write_temp("complex.f06", "  C O M P L E X   E I G E N V A L U E   S U M M A R Y\n")),
                    Catch::Contains("complex.f06:1") && Catch::Contains("complex eigenvalue"));
}

TEST_CASE("nastran f06: the weight generator's MO equals the importer's rigid-body mass matrix", "[nastran][physics]") {
  const auto printed = read_f06_weight(shared_run("beam_modes.f06"));
  REQUIRE(printed);
  CHECK(printed->reference_point == 0);
  const Bulk bulk = read_bulk(shared_run("beam_modes.dat"));
  const Eigen::Matrix<double, 6, 6> MO = rigid_body_mass(lumped_masses(bulk), bulk);
  INFO("printed MO\n" << printed->MO << "\nimporter's MO\n" << MO);
  // to the printed 7 digits of each entry (zeros printed as 0.000000E+00 are zero here to round-off)
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      CHECK(std::abs(MO(i, j) - printed->MO(i, j)) <= 1e-6 * std::abs(printed->MO(i, j)) + 1e-15);
}
