#include "engine/load_model.hpp"

#include "engine/initial_orbit.hpp"

namespace kanegen {

Model load_model(const std::string& path) {
  Model model = parse_model(path);
  if (model.initial_orbit && model.orbit_root >= 0) place_on_orbit(model, model.orbit_root, *model.initial_orbit);
  return model;
}

}  // namespace kanegen
