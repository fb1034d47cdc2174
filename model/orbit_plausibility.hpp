// What `kanegen check` says of an orbit (model-format.md, "Gravity"; docs/decisions.md,
// "Orbits: what check prints and warns of"): its period, perigee and apogee, and warnings
// (never refusals: the contract allows these inputs) where the input looks like a slip —
// an angle outside its range (degrees for radians), a perigee below the central body's
// radius, mu and a in mixed units (km^3/s^2 against metres).
#pragma once

#include <string>
#include <vector>

#include "model/diagnostics.hpp"
#include "model/model.hpp"

namespace kanegen {

struct OrbitDescription {
  double period = 0.0;      ///< 2 pi sqrt(a^3 / mu) [s]
  double r_perigee = 0.0;   ///< a (1 - e) [m]
  double r_apogee = 0.0;    ///< a (1 + e) [m]
  double radius = 0.0;      ///< the central body's radius the altitudes are over; 0: unknown
  std::string radius_from;  ///< "gravity.central.radius" or the body whose GM mu is (e.g. "Earth's mean radius")
  std::vector<Diagnostic> warnings;  ///< file, line, field and what looks wrong; exit 0
};

/// The model's initial orbit described and checked (requires model.central and model.initial_orbit).
OrbitDescription describe_orbit(const Model& model);

}  // namespace kanegen
