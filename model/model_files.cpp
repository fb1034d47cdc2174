#include "model/model_files.hpp"

#include <algorithm>

namespace kanegen {

std::vector<std::string> model_files(const Model& model) {
  std::vector<std::string> files{model.source_path};
  for (const Body& b : model.bodies)
    if (b.flex && !b.flex->source.empty() && b.flex->source != "beam" &&
        std::find(files.begin(), files.end(), b.flex->source) == files.end())
      files.push_back(b.flex->source);
  return files;
}

std::vector<std::string> input_files(const Model& model, const std::string& state_path) {
  std::vector<std::string> files = model_files(model);
  if (!state_path.empty()) files.push_back(state_path);
  return files;
}

}  // namespace kanegen
