// Writers of named matrices and name lists (a linear state-space model's A, B,
// C, D and its state, input and output names) for NumPy (.npz: NPY format 1.0
// entries in a stored zip, PKWARE APPNOTE), MATLAB (Level 5 MAT-file,
// MathWorks "MAT-File Format") and spreadsheets (CSV). Each file is written to
// `path + ".tmp"` and renamed into place; on an I/O error the temporary file
// is removed and std::runtime_error names the path.
#pragma once

#include <Eigen/Dense>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace kanegen {

/// Matrices and name lists by key; keys are identifiers ([A-Za-z_][A-Za-z0-9_]*),
/// distinct across both lists; names are UTF-8.
struct NamedMatrices {
  std::vector<std::pair<std::string, Eigen::MatrixXd>> matrices;        ///< e.g. {"A", A}, {"B", B}
  std::vector<std::pair<std::string, std::vector<std::string>>> names;  ///< e.g. {"state_names", {...}}
};

/// NumPy .npz (a zip archive, entries stored uncompressed, each "<key>.npy" in NPY format 1.0;
/// matrices as '<f8' in C order with their true shape, including 0-row or 0-column shapes;
/// name lists as 1-D '<U{maxlen}' arrays (UTF-32LE, fixed width; maxlen at least 1)).
/// Throws std::invalid_argument for a bad or repeated key or a name that is not UTF-8.
void write_npz(const std::string& path, const NamedMatrices& m);

/// MATLAB Level 5 MAT-file (uncompressed): each matrix a double array (mxDOUBLE_CLASS, miDOUBLE,
/// column-major, true dimensions even when one is 0), each name list an n x 1 cell array
/// (mxCELL_CLASS) of 1 x len char row vectors (mxCHAR_CLASS, miUTF8 data, len in characters: what
/// scipy.io.loadmat decodes by default; it reads miUINT16 chars as single bytes). MATLAB variable
/// names: keys starting with '_' or longer than 63 characters are refused (std::invalid_argument).
void write_mat(const std::string& path, const NamedMatrices& m);

/// CSV: one file per matrix, `<prefix>_<key>.csv`, values with 17 significant digits. `labels`
/// maps a matrix key to the keys of its row and column name lists (e.g. "A" -> {"state_names",
/// "state_names"}); a labelled file's first row is an empty cell then the column labels, and
/// each row starts with its label. A matrix without an entry gets no labels. Fields holding a
/// comma, quote or line break are quoted (RFC 4180). Everything is checked before any file is
/// written (std::invalid_argument: bad key, unknown matrix or name list, label count not the
/// matrix's size). Returns the paths written, in the order of m.matrices.
std::vector<std::string> write_csv(const std::string& prefix, const NamedMatrices& m,
                                   const std::map<std::string, std::pair<std::string, std::string>>& labels);

}  // namespace kanegen
