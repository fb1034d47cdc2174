// The modes of a NASTRAN SOL 103 run as its punch file (.pch) gives them
// (issue 36): the $EIGENVECTOR blocks of MSC and NX/Simcenter Nastran, each
// headed by "$EIGENVALUE = <lambda> MODE = <n>", a row "<grid> G T1 T2 T3" and
// a "-CONT-" row "R1 R2 R3" per grid. Columns 73-80 of every line hold the
// punch's line counter and are not data. Other blocks ($DISPLACEMENTS,
// $ELEMENT FORCES, ...) are skipped; a complex eigenvector block is refused.
#pragma once

#include <string>
#include <vector>

#include "fea/nastran_mode.hpp"

namespace kanegen::nastran {

/// Every mode with an $EIGENVECTOR block, in mode order; the frequency (cycles) is sqrt(eigenvalue) / 2 pi and
/// no generalized mass is given (0). Throws InputError (file, line) for a complex eigenvector block, a file
/// without an eigenvector block, or a row it cannot read.
std::vector<Mode> read_punch_modes(const std::string& path);

}  // namespace kanegen::nastran
