// FEA modal data files (*.modal.yaml, model-format.md) -> FlexibleData.
#pragma once

#include <string>
#include <vector>

#include "model/diagnostics.hpp"
#include "model/model.hpp"

namespace kanegen {

/// Limits of modal data (docs/limits.md), checked before anything is allocated.
inline constexpr std::size_t kMaxModalNodes = 100'000;  ///< nodes in a modal file
inline constexpr std::size_t kMaxFileModes = 2'000;     ///< modes in a modal file
inline constexpr double kMaxShapeEntries = 3e7;          ///< 3 x nodes x modes
inline constexpr int kMaxBodyModes = 500;                ///< modes a body keeps
inline constexpr double kMaxSecondOrderEntries = 3e7;    ///< Sum over nodes and axes of modes^2

/// Reads a modal file: nodes, modes, second-order data; normalizes shapes
/// (and scales second-order data) when mass_normalized is false; keeps the
/// 1-based `keep` subset (all if empty).
/// Faults are appended to `diagnostics` (file, line, field); the result is
/// meaningful only if none were added. `damping_ratio`, K and D are left for
/// the caller (they come from the model file).
FlexibleData load_modal_file(const std::string& path, const std::vector<int>& keep,
                             std::vector<Diagnostic>& diagnostics);

/// The modes `sel` (0-based, in that order) of `flex`, with their shapes,
/// frequencies and second-order rows and columns.
FlexibleData select_modes(const FlexibleData& flex, const std::vector<int>& sel);

/// Diagonal modal masses Y_ii = Sum_k (m_k Phi_k,i.Phi_k,i + Psi_k,i.J_k Psi_k,i)
/// (dynamics.md, "Forces").
Eigen::VectorXd modal_masses(const FlexibleData& flex);

/// Writes FlexibleData in the modal file format (mass_normalized: true),
/// with lossless doubles; read back with load_modal_file it gives the same data.
void write_modal_file(const FlexibleData& flex, const std::string& path);

}  // namespace kanegen
