// A NASTRAN bulk data deck as the modal importer needs it (issue 36): grids
// in the basic frame with their displacement frames, the mass-carrying
// elements with their sections and materials, CONM2 masses, single-point
// constraints and the PARAMs that change the mass (WTMASS, COUPMASS). What
// is not read and could carry mass (plates, solids, CONM1, CMASS, a tapered
// or offset beam) is refused by file, line and card, never guessed.
// Supported: GRID, CORD2R, CORD1R, CBAR, CBEAM, CROD, CONROD, CONM2, PBAR,
// PBARL and PBEAML (ROD, TUBE, BAR, BOX, I), PBEAM (constant section), PROD,
// MAT1, SPC, SPC1, PARAM.
#pragma once

#include <Eigen/Dense>
#include <map>
#include <string>
#include <vector>

#include "fea/nastran_cards.hpp"

namespace kanegen::nastran {

struct Grid {
  int id = 0;
  Eigen::Vector3d x_basic = Eigen::Vector3d::Zero();  ///< position, basic frame
  /// The displacement frame (CD) in basic: displacements u_basic = R_basic_cd u_cd.
  Eigen::Matrix3d R_basic_cd = Eigen::Matrix3d::Identity();
  int cd = 0;
  std::string spc;  ///< the components constrained (SPC, SPC1, PS), e.g. "123456"
  std::string file;
  int line = 0;
};

/// A line element's mass-relevant data.
struct LineElement {
  std::string type;  ///< CBAR, CBEAM, CROD, CONROD
  int id = 0;
  int ga = 0, gb = 0;
  double area = 0.0;     ///< A
  double J = 0.0;        ///< torsion constant
  double rho = 0.0;      ///< the material's density (MAT1 RHO)
  double nsm = 0.0;      ///< non-structural mass per length
  std::string file;
  int line = 0;
};

struct PointMass {  ///< CONM2
  int id = 0;
  int grid = 0;
  double mass = 0.0;
  Eigen::Vector3d offset_basic = Eigen::Vector3d::Zero();  ///< from the grid to the mass's centre, basic frame
  Eigen::Matrix3d inertia_basic = Eigen::Matrix3d::Zero();  ///< about its centre, basic axes
  std::string file;
  int line = 0;
};

struct Bulk {
  std::map<int, Grid> grids;
  std::vector<LineElement> elements;
  std::vector<PointMass> masses;
  double wtmass = 1.0;  ///< PARAM WTMASS: the structural mass is this times the input mass
  int grdpnt = -1;      ///< PARAM GRDPNT: the weight generator's reference grid (0: basic origin; -1: none)
};

/// Reads a deck (read_cards) into a Bulk. Throws InputError (file, line, card, field) for what it cannot read:
/// an unsupported mass-carrying card, COUPMASS > 0, a missing or unsupported property or material, a grid in
/// a cylindrical or spherical frame, a beam with offsets or a tapered section.
Bulk read_bulk(const std::string& path);

/// The lumped mass of one grid, NASTRAN's default lumped formulation, in the basic frame (input mass units,
/// before WTMASS): translational mass, and the 3 x 3 rotary inertia about the grid; `coupling` is the
/// translation-rotation block (from offset CONM2s: m [d]x^T).
struct GridMass {
  double mass = 0.0;
  Eigen::Matrix3d coupling = Eigen::Matrix3d::Zero();  ///< M_tr: force from rotation
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};

/// Line elements: (rho A + NSM) L / 2 of translational mass at each end; a CBEAM adds rho J L / 2 of
/// torsional inertia about its axis at each end (NX/Simcenter's lumped CBEAM; a CBAR adds none). CONM2: its
/// mass at the grid, moved by its offset (the parallel-axis terms and the coupling).
std::map<int, GridMass> lumped_masses(const Bulk& bulk);

/// What NASTRAN's grid point weight generator prints, in input mass units (WTMASS not applied, as NASTRAN
/// prints it): mass, centre of mass and inertia about it, basic frame.
struct WeightSummary {
  double mass = 0.0;
  Eigen::Vector3d cg = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia_cg = Eigen::Matrix3d::Zero();  ///< I(S): about the centre of mass, basic axes
};
WeightSummary weight_summary(const std::map<int, GridMass>& masses, const Bulk& bulk);
/// The same read from a rigid-body mass matrix MO about the point x_ref (basic): NASTRAN's printed one or ours.
WeightSummary weight_summary(const Eigen::Matrix<double, 6, 6>& MO, const Eigen::Vector3d& x_ref);

/// The rigid-body mass matrix about the point x_ref (basic), NASTRAN's weight generator's MO: the sum over grids
/// of D^T M_g D with D mapping a rigid motion (t, r) at x_ref to the grid's (t - [x - x_ref]x r, r).
Eigen::Matrix<double, 6, 6> rigid_body_mass(const std::map<int, GridMass>& masses, const Bulk& bulk,
                                            const Eigen::Vector3d& x_ref = Eigen::Vector3d::Zero());

}  // namespace kanegen::nastran
