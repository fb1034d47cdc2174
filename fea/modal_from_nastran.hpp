// A flexible body's modal data from a NASTRAN SOL 103 run (issue 36): the
// bulk data's grids and lumped mass (fea/nastran_bulk.hpp) joined with the
// run's modes (fea/nastran_f06.hpp or fea/nastran_punch.hpp), in the body
// frame of the modal file contract (model-format.md, "Modal data file"):
//   - origin at the root grid (the clamped interface), axes NASTRAN's basic
//     axes; positions x_basic - x_root;
//   - a node per grid that carries mass or ends an element; a grid with
//     neither (e.g. one AUTOSPC removed) is dropped with a note;
//   - node masses and rotary inertias from the lumping, times WTMASS; a
//     grid whose mass is off the grid (an offset CONM2) gives its mass to a
//     node of its own at the mass centre, moving rigidly with the grid
//     (translation t + r x d), the grid's node keeping none;
//   - shapes turned from each grid's displacement frame (CD) to basic, then
//     mass-normalized with that mass (modal_masses(), the contract's rule);
//   - frequencies NASTRAN's cycles (Hz).
// The checks that prove the mass against NASTRAN's own printout are kept in
// the result: the generalized masses (f06) against phi^T M phi, the weight
// generator's MO against the lumped mass, the root's motion in every mode.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "fea/nastran_bulk.hpp"
#include "fea/nastran_f06.hpp"
#include "fea/nastran_mode.hpp"
#include "model/model.hpp"

namespace kanegen::nastran {

struct ModalImportOptions {
  int root = 0;  ///< the clamped grid at the body origin; 0: the single grid with SPC 123456
  /// Write the data even when the lumped mass is not NASTRAN's (a check beyond kMassCheckTolerance); else
  /// such a run is refused with the figures.
  bool accept_mass_mismatch = false;
};

/// Beyond this relative difference a check against NASTRAN's printout fails (the f06 prints 7 digits).
inline constexpr double kMassCheckTolerance = 1e-4;

/// One mode's generalized mass: as NASTRAN printed it, and phi^T M phi with the importer's mass (both in
/// NASTRAN's normalization of the shapes).
struct GeneralizedMassCheck {
  int mode = 0;
  double printed = 0.0;
  double computed = 0.0;
  double relative_error() const { return std::abs(computed - printed) / std::abs(printed); }
};

struct ModalImport {
  FlexibleData flex;                  ///< mass-normalized, ready for write_modal_file
  int root = 0;                       ///< the root grid
  std::vector<int> modes;             ///< NASTRAN's number of each mode of flex, in order
  std::vector<std::string> notes;     ///< what was dropped, moved or is worth knowing
  double total_mass = 0.0;            ///< the nodes' mass (WTMASS applied)
  std::vector<GeneralizedMassCheck> generalized_masses;  ///< f06 only: one per mode printed with a mass
  /// The weight generator's MO (f06) against the lumped mass's, about the same point: max |difference| over
  /// max |MO|; nullopt without a weight generator printout.
  std::optional<double> weight_generator_error;
  /// With a weight generator printout: its mass, centre of mass and inertia about it, and the lumped mass's
  /// (input units, basic frame), and their relative differences (the centre of mass's over the radius of
  /// gyration, the inertia's over its largest entry).
  std::optional<WeightSummary> printed_weight, lumped_weight;
  double mass_error = 0.0, cg_error = 0.0, inertia_error = 0.0;
  /// The checks beyond kMassCheckTolerance, with their figures (empty: all passed).
  std::vector<std::string> mismatches;
  std::string weight_generator_note;  ///< why there is no weight generator check (when there is none)
  /// max over modes of the root's largest displacement or rotation over the mode's largest entry.
  double root_motion = 0.0;
};

/// The modal data of the structure in `bulk` (read from `bulk_path`) with the modes `modes` (read from
/// `modes_path`; modes without an eigenvector are left out with a note). `weight`: the f06's weight generator
/// output, if any. Throws InputError (naming the file and what) when no root can be chosen, the root moves in a
/// mode (the run is not clamped there), a grid that carries mass has no shape, or no mode has a shape.
ModalImport import_modal_data(const Bulk& bulk, const std::string& bulk_path, const std::vector<Mode>& modes,
                              const std::string& modes_path, const std::optional<F06Weight>& weight,
                              const ModalImportOptions& options = {});

}  // namespace kanegen::nastran
