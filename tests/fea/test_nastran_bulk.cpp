// NASTRAN bulk data (fea/nastran_cards, fea/nastran_bulk; issue 36): the
// shared Simcenter Nastran SOL 103 run's deck (tests/data/fea/
// pynastran_beam_modes, a copy of ../shared/fea-data with its SOURCE.md)
// lumped as NASTRAN lumps it gives back the grid point weight generator's
// printed mass, centre of mass and inertia; the three field formats and
// their continuations read the same deck alike; a CONM2 offset in a rotated
// frame against the parallel-axis closed form; refusals by file, line, card.
#include <catch2/catch.hpp>

#include <fmt/format.h>

#include <fstream>

#include "fea/nastran_bulk.hpp"
#include "fea/nastran_cards.hpp"
#include "model/diagnostics.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;
using namespace kanegen::nastran;

namespace {

using test::shared_run;

std::string refusal(const std::string& name, const std::string& text) {
  try {
    read_bulk(test::write_temp(name, text));
  } catch (const InputError& e) {
    return e.diagnostics().at(0).str();
  }
  return "(accepted)";
}

}  // namespace

TEST_CASE("nastran: real fields in NASTRAN's forms", "[nastran]") {
  CHECK(*parse_real("1.5") == 1.5);
  CHECK(*parse_real("2.5900-3") == Approx(2.59e-3).epsilon(1e-15));
  CHECK(*parse_real("3.0000+7") == 3.0e7);
  CHECK(*parse_real(".29") == 0.29);
  CHECK(*parse_real("-.5E-2") == -0.005);
  CHECK(*parse_real("1.0D-3") == 1.0e-3);
  CHECK(*parse_real("7.4851-4") == Approx(7.4851e-4).epsilon(1e-15));
  CHECK(*parse_real("-1.-2") == -0.01);
  CHECK(*parse_real("2.") == 2.0);
  CHECK(*parse_real("12") == 12.0);
  CHECK_FALSE(parse_real("ABC"));
  CHECK_FALSE(parse_real("1.5X"));
  CHECK_FALSE(parse_real(""));
}

TEST_CASE("nastran: the shared SOL 103 deck lumped as NASTRAN lumps it gives the grid point weight generator's "
          "mass, centre of mass and inertia",
          "[nastran][physics]") {
  const Bulk bulk = read_bulk(shared_run("beam_modes.dat"));  // INCLUDE 'cbar_cbeam.blk'
  CHECK(bulk.grids.size() == 12);
  CHECK(bulk.elements.size() == 10);
  REQUIRE(bulk.masses.size() == 1);
  CHECK(bulk.grids.at(1).spc == "123456");
  CHECK(bulk.grids.at(11).x_basic.x() == 10.0);
  CHECK(bulk.grdpnt == 0);
  CHECK(bulk.wtmass == 1.0);
  const WeightSummary w = weight_summary(lumped_masses(bulk), bulk);
  // as beam_modes.f06 prints them (O U T P U T   F R O M   G R I D   P O I N T   W E I G H T   G E N E R A T O R)
  CHECK(w.mass == Approx(2.610514e-2).epsilon(1e-6));
  CHECK(w.cg.x() == Approx(5.496071).epsilon(1e-6));
  CHECK(std::abs(w.cg.y()) <= 1e-15);
  CHECK(std::abs(w.cg.z()) <= 1e-15);
  // Ixx = the CONM2's 2.59e-3 + the CBEAM's rho J L (half at each end): torsional inertia a CBAR does not add
  CHECK(w.inertia_cg(0, 0) == Approx(3.765757e-3).epsilon(1e-6));
  CHECK(w.inertia_cg(1, 1) == Approx(2.607945e-1).epsilon(1e-6));
  CHECK(w.inertia_cg(2, 2) == Approx(2.607945e-1).epsilon(1e-6));
  CHECK(std::abs(w.inertia_cg(0, 1)) + std::abs(w.inertia_cg(0, 2)) + std::abs(w.inertia_cg(1, 2)) <= 1e-15);
}

TEST_CASE("nastran: small, large and free field, with continuations, read one deck alike", "[nastran]") {
  // the same deck three times: a beam of two CBARs from grid 1, a CONM2 with a continuation
  const std::string small = R"($ small field
GRID           1       0     0.0     0.0     0.0       0  123456
GRID           2       0     1.5     0.0     0.0       0
GRID           3       0     3.0     0.5     0.0       0
CBAR          10       7       1       2     0.0     1.0     0.0
CBAR          11       7       2       3     0.0     1.0     0.0
PBAR           7       5    0.25  1.0E-3  2.0E-3  3.0E-3    0.01
MAT1           5  7.0+10             0.3   2700.
CONM2         21       3       0    12.5     0.1     0.2    -0.3        +C1
+C1          1.0     0.1     2.0     0.2     0.3     3.0
)";
  const std::string large = R"($ large field
GRID*                  1               0             0.0             0.0
*                    0.0               0          123456
GRID*                  2               0             1.5             0.0
*                    0.0               0
GRID*                  3               0             3.0             0.5
*                    0.0               0
CBAR*                 10               7               1               2
*                    0.0             1.0             0.0
CBAR*                 11               7               2               3
*                    0.0             1.0             0.0
PBAR*                  7               5            0.25          1.0E-3
*                 2.0E-3          3.0E-3            0.01
MAT1*                  5         7.0E+10                             0.3
*                 2700.0
CONM2*                21               3               0            12.5
*                    0.1             0.2            -0.3
*                    1.0             0.1             2.0             0.2
*                    0.3             3.0
)";
  const std::string free = R"($ free field, and a card split with a blank first field
GRID,1,0,0.0,0.0,0.0,0,123456
GRID,2,,1.5,0.,0.
GRID,3,,3.,.5,0.
CBAR,10,7,1,2,0.,1.,0.
CBAR,11,7,2,3,0.,1.,0.
PBAR,7,5,.25,1.-3,2.-3,3.-3,.01
MAT1,5,7.+10,,.3,2700.
CONM2,21,3,0,12.5,.1,.2,-.3,,+C1
+C1,1.,.1,2.,.2,.3,3.
)";
  const Bulk a = read_bulk(test::write_temp("small.bdf", small));
  const Bulk b = read_bulk(test::write_temp("large.bdf", large));
  const Bulk c = read_bulk(test::write_temp("free.bdf", free));
  for (const Bulk* x : {&b, &c}) {
    REQUIRE(x->grids.size() == 3);
    REQUIRE(x->elements.size() == 2);
    REQUIRE(x->masses.size() == 1);
    for (const auto& [id, g] : a.grids) {
      CHECK(x->grids.at(id).x_basic == g.x_basic);
      CHECK(x->grids.at(id).spc == g.spc);
    }
    CHECK(x->elements[1].area == 0.25);
    CHECK(x->elements[1].J == 3.0e-3);
    CHECK(x->elements[1].nsm == 0.01);
    CHECK(x->elements[1].rho == 2700.0);
    CHECK(x->masses[0].offset_basic == a.masses[0].offset_basic);
    CHECK(x->masses[0].inertia_basic == a.masses[0].inertia_basic);
  }
  CHECK(a.grids.at(1).spc == "123456");
  CHECK(a.masses[0].inertia_basic(0, 1) == -0.1);  // I21 enters with a minus
  CHECK(a.masses[0].inertia_basic(2, 2) == 3.0);
  // the lumping: each CBAR's (rho A + NSM) L / 2 at its ends
  const auto m = lumped_masses(a);
  const double L2 = std::hypot(1.5, 0.5);
  CHECK(m.at(1).mass == Approx((2700.0 * 0.25 + 0.01) * 1.5 / 2).epsilon(1e-15));
  CHECK(m.at(2).mass == Approx((2700.0 * 0.25 + 0.01) * (1.5 + L2) / 2).epsilon(1e-15));
  CHECK(m.at(3).mass == Approx((2700.0 * 0.25 + 0.01) * L2 / 2 + 12.5).epsilon(1e-15));
}

TEST_CASE("nastran: a CONM2 offset in a rotated CORD2R frame against the parallel-axis closed form",
          "[nastran][physics]") {
  // frame 4: origin (1, 2, 3), its z along basic x, its x along basic y (CORD2R A, B on z, C in the x-z plane)
  const Bulk bulk = read_bulk(test::write_temp("conm2_offset.bdf", R"(CORD2R,4,0,1.,2.,3.,2.,2.,3.,+
+,1.,3.,3.
GRID,1,4,0.,0.,1.
CONM2,8,1,4,2.,.5,0.,0.,,+
+,1.,0.,2.,0.,0.,3.
)"));
  // grid 1 at frame 4's z = 1: basic (2, 2, 3); the offset (0.5, 0, 0) in frame 4 is 0.5 along basic y
  CHECK((bulk.grids.at(1).x_basic - Eigen::Vector3d(2, 2, 3)).norm() <= 1e-15);
  const WeightSummary w = weight_summary(lumped_masses(bulk), bulk);
  CHECK(w.mass == 2.0);
  CHECK((w.cg - Eigen::Vector3d(2, 2.5, 3)).norm() <= 1e-15);
  // about its own centre: the CONM2's inertia in basic axes (frame 4's x, y, z are basic y, z, x)
  CHECK(w.inertia_cg(0, 0) == Approx(3.0).epsilon(1e-14));
  CHECK(w.inertia_cg(1, 1) == Approx(1.0).epsilon(1e-14));
  CHECK(w.inertia_cg(2, 2) == Approx(2.0).epsilon(1e-14));
  // and about the grid: the parallel-axis terms m (|d|^2 - d d^T) and the coupling -m [d]x
  const GridMass g = lumped_masses(bulk).at(1);
  CHECK(g.inertia(0, 0) == Approx(3.0 + 2.0 * 0.25).epsilon(1e-14));
  CHECK(g.inertia(1, 1) == Approx(1.0).epsilon(1e-14));
  CHECK(g.inertia(2, 2) == Approx(2.0 + 2.0 * 0.25).epsilon(1e-14));
  CHECK(g.coupling(0, 2) == Approx(-2.0 * 0.5).epsilon(1e-14));  // -m [d]x with d = (0, 0.5, 0): (0,2) = -m d_y
}

TEST_CASE("nastran: what the importer cannot lump is refused by file, line and card", "[nastran]") {
  const std::string grids = "GRID,1,,0.,0.,0.\nGRID,2,,1.,0.,0.\nGRID,3,,1.,1.,0.\nMAT1,5,7.+10,,.3,2700.\n";
  CHECK_THAT(refusal("quad.bdf", grids + "CQUAD4,9,3,1,2,3,3\n"),
             Catch::Contains("quad.bdf:5") && Catch::Contains("CQUAD4") && Catch::Contains("not supported"));
  CHECK_THAT(refusal("coupmass.bdf", grids + "PARAM,COUPMASS,1\n"),
             Catch::Contains("coupmass.bdf:5") && Catch::Contains("COUPMASS"));
  CHECK_THAT(refusal("noprop.bdf", grids + "CBAR,10,7,1,2,0.,1.,0.\n"),
             Catch::Contains("noprop.bdf:5") && Catch::Contains("CBAR 10") && Catch::Contains("property 7 is not defined"));
  CHECK_THAT(refusal("nomat.bdf", grids + "CROD,10,7,1,2\nPROD,7,6,.2\n"),
             Catch::Contains("nomat.bdf:6") && Catch::Contains("material 6 is not defined"));
  CHECK_THAT(refusal("offset.bdf", grids + "CBAR,10,7,1,2,0.,1.,0.,,+\n+,,,0.,.1,0.\nPBAR,7,5,.25\n"),
             Catch::Contains("offset.bdf:5") && Catch::Contains("offset"));
  CHECK_THAT(refusal("cyl.bdf", "CORD2C,3,0,0.,0.,0.,0.,0.,1.,+\n+,1.,0.,0.\nGRID,1,3,1.,0.,0.\n"),
             Catch::Contains("cyl.bdf:1") && Catch::Contains("CORD2C"));
  CHECK_THAT(refusal("nocoord.bdf", "GRID,1,8,1.,0.,0.\n"),
             Catch::Contains("nocoord.bdf:1") && Catch::Contains("coordinate system 8 is not defined"));
  CHECK_THAT(refusal("badreal.bdf", "GRID,1,,1.x,0.,0.\n"),
             Catch::Contains("badreal.bdf:1") && Catch::Contains("GRID 1") && Catch::Contains("'1.x'"));
  CHECK_THAT(refusal("orphan.bdf", "+,1.,2.\n"), Catch::Contains("orphan.bdf:1") && Catch::Contains("continuation"));
  CHECK_THAT(refusal("loop.bdf", "INCLUDE 'loop.bdf'\n"), Catch::Contains("includes itself"));
  CHECK_THAT(refusal("missing.bdf", "INCLUDE 'no_such_file.blk'\n"),
             Catch::Contains("missing.bdf:1") && Catch::Contains("cannot read"));
  CHECK_THAT(refusal("tapered.bdf", grids + "CBEAM,10,7,1,2,0.,1.,0.\nPBEAML,7,5,,TUBE,,,,,+\n+,1.,.5,0.,YES,1.,1.,.4\n"),
             Catch::Contains("tapered"));
}
