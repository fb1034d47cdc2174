// Model -> one self-contained, specialized C++ header (templates/model.hpp.in).
#pragma once

#include <map>
#include <string>

#include "model.hpp"
#include "program.hpp"

namespace kanegen::gen {

struct GeneratedCode {
  std::string header;
  std::map<std::string, OpCount> ops;  ///< per emitted function (and udot_composite, udot_articulated)
  std::string udot_form;               ///< "composite" or "articulated": the one emitted
};

struct GeneratorOptions {
  bool merge_fixed = true;  ///< merge rigid bodies on fixed joints into their parents
  std::string template_dir; ///< empty: KANEGEN_SOURCE_DIR/templates
  std::string udot_form = "auto";  ///< "auto" (fewer operations), "composite" or "articulated"
};

GeneratedCode generate(const Model& model, const GeneratorOptions& options = {});

/// generate(model).header
std::string generate_header(const Model& model);

}  // namespace kanegen::gen
