// The manifest of one model's generated code (written by codegen/assembler.cpp
// next to the header and the entry file): what the JIT and
// kanegen_add_model() need to know without reading any C++.
#pragma once

#include <string>
#include <vector>

namespace kanegen {

struct ManifestFunction {
  std::string name;
  long ops = 0;       ///< operation count of the function (jacobian: an estimate of its dual passes)
  int out_size = 0;
};

struct Manifest {
  std::string model, identifier, name_space, api_symbol;
  std::string model_hash, generator_hash, generator_version;
  int nq = 0, nu = 0, nbodies = 0;
  int nw = 0, ny = 0;  ///< named inputs and outputs
  int np = 0;          ///< runtime parameters
  std::string udot_form;
  /// How u-dot is emitted: "straight-line" (one function), "straight-line in parts" or "compact"
  /// (outlined_code.hpp); empty in older manifests.
  std::string udot_code;
  std::vector<ManifestFunction> functions;
  const ManifestFunction* find(const std::string& name) const;
};

/// Parses manifest JSON; throws std::runtime_error naming `what` (a path or
/// a description) and the missing or malformed field.
Manifest parse_manifest(const std::string& json_text, const std::string& what);

}  // namespace kanegen
