// The files a model is read from, and the files a command on it reads: what
// a dependency file lists and what no output of a command may overwrite
// (check_output_options, issue 34).
#pragma once

#include <string>
#include <vector>

#include "model/model.hpp"

namespace kanegen {

/// The model's YAML file, then each modal file its flexible bodies name
/// (once each, in body order; a beam: block reads none).
std::vector<std::string> model_files(const Model& model);

/// model_files(model), and the state file when `state_path` is not empty.
std::vector<std::string> input_files(const Model& model, const std::string& state_path);

}  // namespace kanegen
