// FEA modal data files (*.modal.yaml, model-format.md) -> FlexibleData.
#pragma once

#include <string>
#include <vector>

#include "model/diagnostics.hpp"
#include "model/model.hpp"

namespace kanegen {

/// Reads a modal file: nodes, modes; normalizes shapes when
/// mass_normalized is false; keeps the 1-based `keep` subset (all if empty).
/// Faults are appended to `diagnostics` (file, line, field); the result is
/// meaningful only if none were added. `damping_ratio`, K and D are left for
/// the caller (they come from the model file).
FlexibleData load_modal_file(const std::string& path, const std::vector<int>& keep,
                             std::vector<Diagnostic>& diagnostics);

/// Writes FlexibleData in the modal file format (mass_normalized: true),
/// with lossless doubles; read back with load_modal_file it gives the same data.
void write_modal_file(const FlexibleData& flex, const std::string& path);

}  // namespace kanegen
