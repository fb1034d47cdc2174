#include "engine/manifest.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <stdexcept>

namespace kanegen {

const ManifestFunction* Manifest::find(const std::string& name) const {
  for (const auto& f : functions)
    if (f.name == name) return &f;
  return nullptr;
}

Manifest parse_manifest(const std::string& text, const std::string& what) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(fmt::format("{}: not a kanegen manifest: {}", what, e.what()));
  }
  Manifest m;
  try {
    if (j.at("format").get<int>() != 1)
      throw std::runtime_error(fmt::format("{}: manifest format {} unknown; expected 1", what, j.at("format").dump()));
    m.model = j.at("model").get<std::string>();
    m.identifier = j.at("identifier").get<std::string>();
    m.name_space = j.at("namespace").get<std::string>();
    m.api_symbol = j.at("api_symbol").get<std::string>();
    m.model_hash = j.at("model_hash").get<std::string>();
    m.generator_hash = j.at("generator_hash").get<std::string>();
    m.generator_version = j.value("generator_version", "");
    m.nq = j.at("nq").get<int>();
    m.nu = j.at("nu").get<int>();
    m.nbodies = j.at("nbodies").get<int>();
    m.nw = j.value("nw", 0);
    m.ny = j.value("ny", 0);
    m.np = j.value("np", 0);
    m.udot_form = j.value("udot_form", "");
    m.udot_code = j.value("udot_code", "");
    for (const auto& f : j.at("functions"))
      m.functions.push_back({f.at("name").get<std::string>(), f.at("ops").get<long>(), f.at("out_size").get<int>()});
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(fmt::format("{}: malformed kanegen manifest: {}", what, e.what()));
  }
  return m;
}

}  // namespace kanegen
