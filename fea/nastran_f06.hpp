// The modes of a NASTRAN SOL 103 run as its .f06 prints them (issue 36): the
// REAL EIGENVALUES table (eigenvalue, cycles, generalized mass) and the REAL
// EIGENVECTOR blocks (T1 T2 T3 R1 R2 R3 per grid, in each grid's output frame),
// in the layouts of MSC and NX/Simcenter Nastran; a block continued over pages
// is joined. A complex eigenvalue solution is refused.
#pragma once

#include <Eigen/Dense>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fea/nastran_mode.hpp"

namespace kanegen::nastran {

/// Every mode of the eigenvalue table, with its eigenvector where the f06 prints one. Throws InputError (file,
/// line) for a complex eigenvalue solution, a file without a REAL EIGENVALUES table, or a row it cannot read.
std::vector<Mode> read_f06_modes(const std::string& path);

/// The grid point weight generator's MO (6 x 6 rigid-body mass matrix about its reference point) and that
/// point (PARAM GRDPNT: 0 the basic origin, else a grid id), if the f06 prints it.
struct F06Weight {
  int reference_point = 0;
  Eigen::Matrix<double, 6, 6> MO = Eigen::Matrix<double, 6, 6>::Zero();
};
std::optional<F06Weight> read_f06_weight(const std::string& path);

}  // namespace kanegen::nastran
