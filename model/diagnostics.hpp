// Errors in user input (model files, modal data, state files): every fault is
// a Diagnostic naming file, line and field; a refused input throws InputError
// carrying all of them. The CLI prints one line per diagnostic and exits 2.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace kanegen {

struct Diagnostic {
  std::string file;     ///< path as given by the user
  int line = 0;         ///< 1-based; 0 when unknown (e.g. a missing file)
  std::string field;    ///< e.g. "bodies[2].joint.axis"
  std::string message;  ///< what is wrong and what is expected
  /// "file:line: field: message" (line and field omitted when unknown/empty)
  std::string str() const;
};

class InputError : public std::runtime_error {
 public:
  explicit InputError(std::vector<Diagnostic> diagnostics);
  explicit InputError(Diagnostic diagnostic);
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }

 private:
  std::vector<Diagnostic> diagnostics_;
};

}  // namespace kanegen
