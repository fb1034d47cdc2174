#include "model/orbit_plausibility.hpp"

#include <cmath>
#include <numbers>
#include <optional>

#include <fmt/format.h>

namespace kanegen {

namespace {


/// Gravitational parameters (m^3/s^2) and mean radii (m) of the Sun and the planets and the Moon
/// (IAU 2015 / JPL DE440 values, rounded): to recognize a mu given in the wrong units.
struct CentralBody {
  const char* name;
  double gm;
  double radius;
};
constexpr CentralBody kBodies[] = {
    {"the Sun", 1.32712440018e20, 6.957e8}, {"Mercury", 2.2031868e13, 2.4397e6}, {"Venus", 3.24858592e14, 6.0518e6},
    {"the Earth", 3.986004418e14, 6.3710e6}, {"the Moon", 4.9028e12, 1.7374e6}, {"Mars", 4.282837e13, 3.3895e6},
    {"Jupiter", 1.26686534e17, 6.9911e7},    {"Saturn", 3.7931187e16, 5.8232e7}, {"Uranus", 5.793939e15, 2.5362e7},
    {"Neptune", 6.836529e15, 2.4622e7}};

/// The body whose GM is within 0.5 % of gm, or none.
std::optional<CentralBody> body_with_gm(double gm) {
  for (const CentralBody& b : kBodies)
    if (std::abs(gm - b.gm) <= 5e-3 * b.gm) return b;
  return std::nullopt;
}

}  // namespace

OrbitDescription describe_orbit(const Model& model) {
  const CentralGravity& c = *model.central;
  const InitialOrbit& o = *model.initial_orbit;
  const OrbitElements& el = o.elements;
  OrbitDescription d;
  d.period = 2.0 * std::numbers::pi * std::sqrt(el.a * el.a * el.a / c.mu);
  d.r_perigee = el.a * (1.0 - el.e);
  d.r_apogee = el.a * (1.0 + el.e);
  const std::optional<CentralBody> si = body_with_gm(c.mu);
  if (c.radius > 0.0) {
    d.radius = c.radius;
    d.radius_from = "gravity.central.radius";
  } else if (si) {
    d.radius = si->radius;
    d.radius_from = fmt::format("the mean radius of {} (mu is its GM)", si->name);
  }
  auto warn = [&](const std::string& field, const std::string& message) {
    d.warnings.push_back(Diagnostic{model.source_path, o.line, field, message});
  };
  // angles: radians (model-format.md); a value beyond its range is most likely degrees
  struct Angle {
    const char* key;
    double value, low, high;
    const char* range;
  };
  for (const Angle& a : {Angle{"i", el.i, 0.0, std::numbers::pi, "[0, pi]"}, Angle{"raan", el.raan, -2 * std::numbers::pi, 2 * std::numbers::pi, "[-2 pi, 2 pi]"},
                         Angle{"argp", el.argp, -2 * std::numbers::pi, 2 * std::numbers::pi, "[-2 pi, 2 pi]"},
                         Angle{"nu", el.nu, -2 * std::numbers::pi, 2 * std::numbers::pi, "[-2 pi, 2 pi]"}})
    if (a.value < a.low || a.value > a.high)
      warn(fmt::format("initial.orbit.{}", a.key),
           fmt::format("{} rad is outside {}; angles are in radians ({} degrees would be {:.6g} rad)", a.value,
                       a.range, a.value, a.value * std::numbers::pi / 180.0));
  // mu in km^3/s^2 with a in metres (or the other way round)
  if (const std::optional<CentralBody> km = body_with_gm(c.mu * 1e9))
    warn("initial.orbit.a",
         fmt::format("a = {:.6g} m with mu = {:.10g} (gravity.central.mu) looks like mixed units: that mu is the GM of "
                     "{} in km^3/s^2 (the orbital period is then {:.3g} days); the units are m^3/s^2 and m: "
                     "expected mu = {:.10g}",
                     el.a, c.mu, km->name, d.period / 86400.0, km->gm));
  if (d.radius > 0.0 && d.r_perigee < d.radius)
    warn("initial.orbit.a",
         fmt::format("the perigee a (1 - e) = {:.6g} m is below the central body's radius {:.6g} m ({}){}",
                     d.r_perigee, d.radius, d.radius_from,
                     d.r_perigee * 1e3 > d.radius ? "; a looks like kilometres: the units are m" : ""));
  return d;
}

}  // namespace kanegen
