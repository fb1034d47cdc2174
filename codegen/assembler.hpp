// EmittedModel (emitted_code.hpp) -> the files of one model's generated code:
// the header (templates/model.hpp.in), the C entry (templates/entry.cpp.in)
// and the JSON manifest. The only place that knows how a function's
// argument list is written in C++ and passed through the C table.
#pragma once

#include <string>

#include "codegen/emitted_code.hpp"

namespace kanegen::codegen {

struct AssembledFiles {
  std::string header;    ///< self-contained model header (<cmath> only)
  std::string entry;     ///< C entry file: #includes the header by `header_name`
  std::string manifest;  ///< JSON: functions, operation counts, namespace, hashes
};

/// `template_dir` holds model.hpp.in and entry.cpp.in; `header_name` is how
/// the entry file #includes the header (e.g. "model.hpp").
AssembledFiles assemble(const EmittedModel& model, const std::string& template_dir, const std::string& header_name);

/// Name of the C function returning the model's table: "kanegen_api_<identifier>".
std::string api_symbol(const EmittedModel& model);

}  // namespace kanegen::codegen
