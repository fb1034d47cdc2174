// One normal mode of a NASTRAN SOL 103 run, as its f06 or its punch file
// gives it (fea/nastran_f06.hpp, fea/nastran_punch.hpp).
#pragma once

#include <Eigen/Dense>
#include <map>

namespace kanegen::nastran {

struct Mode {
  int number = 0;              ///< the mode number NASTRAN prints
  double eigenvalue = 0.0;     ///< (rad/s)^2
  double cycles = 0.0;         ///< Hz
  /// As printed in the f06's eigenvalue table; 0 where the source prints none (a punch file).
  double generalized_mass = 0.0;
  /// Per grid id: [T1 T2 T3 R1 R2 R3] in the grid's displacement (CD) frame, as printed.
  std::map<int, Eigen::Matrix<double, 6, 1>> shapes;
};

}  // namespace kanegen::nastran
