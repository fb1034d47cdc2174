// Two-body orbits about a central body at N's origin (model-format.md,
// "Gravity"): classical elements to position and velocity and back, Kepler's
// equation, and the orbit (LVLH) frame. The pieces `initial: orbit:` and the
// orbit-frame sensors are built from; closed forms only, no integration.
#pragma once

#include <Eigen/Dense>

namespace kanegen {

/// Classical elements (m, radians): semi-major axis a > 0, eccentricity 0 <= e < 1, inclination i,
/// right ascension of the ascending node raan, argument of periapsis argp, true anomaly nu.
struct OrbitElements {
  double a = 0, e = 0, i = 0, raan = 0, argp = 0, nu = 0;
};

/// `initial: orbit:` (model-format.md, "Gravity"): the elements of the orbit the system's centre of mass is
/// placed on; with lvlh the root body aligned with the orbit frame L, turned by R_LB, and turning with L plus
/// rate_offset_B (its angular velocity relative to L, B components).
struct InitialOrbit {
  OrbitElements elements;
  bool lvlh = false;
  Eigen::Matrix3d R_LB = Eigen::Matrix3d::Identity();
  Eigen::Vector3d rate_offset_B = Eigen::Vector3d::Zero();
  int line = 0;  ///< of `orbit:` in the model file (0: not from a file)
};

struct OrbitState {
  Eigen::Vector3d r_N = Eigen::Vector3d::Zero();  ///< position from the central body, N components
  Eigen::Vector3d v_N = Eigen::Vector3d::Zero();  ///< velocity, N components
};

/// Position and velocity on the elliptic orbit (throws std::invalid_argument unless mu > 0, a > 0, 0 <= e < 1).
OrbitState state_from_elements(double mu, const OrbitElements& el);

/// The elements of a bound state (throws std::invalid_argument for e >= 1 or r, v not finite); for a circular or
/// equatorial orbit the undefined angles are taken 0 and the anomaly measured from the node or the x axis.
OrbitElements elements_from_state(double mu, const OrbitState& s);

/// The eccentric anomaly E of mean anomaly M (E - e sin E = M), to round-off, for 0 <= e < 1.
double eccentric_anomaly(double M, double e);

/// The true anomaly after time t on the unperturbed orbit (Kepler's equation).
double true_anomaly_at(double mu, const OrbitElements& el, double t);

/// Orbital period 2 pi sqrt(a^3 / mu).
double orbital_period(double mu, double a);

/// The orbit frame at a state, its axes as the columns of R_N_O (x_N = R_N_O x_O): z to nadir (-r),
/// y against the orbit normal (-h), x = y x z (along track; the velocity's direction on a circular orbit).
Eigen::Matrix3d lvlh_frame(const OrbitState& s);

/// The orbit frame's angular velocity, N components: h / |r|^2 (about the orbit normal).
Eigen::Vector3d lvlh_rate_N(const OrbitState& s);

// The orbit-frame sensors' values (model/inputs_outputs.hpp), by the rules of
// templates/orbit_frame.inc that the generated code shares; s is the system's
// centre of mass.
/// attitude_lvlh: [qw, qx, qy, qz] of R_LX (qw >= 0), then its rotation vector [roll, pitch, yaw].
Eigen::Matrix<double, 7, 1> attitude_lvlh(const OrbitState& s, const Eigen::Matrix3d& R_NX);
/// angular_velocity_lvlh: w_X - R_XN w_L, X components (w_X: the body's angular velocity in X axes).
Eigen::Vector3d angular_velocity_lvlh(const OrbitState& s, const Eigen::Matrix3d& R_NX, const Eigen::Vector3d& w_X);
/// orbit_elements: [a, e, i, raan, argp, nu] of the state (no check that it is bound: a < 0 if not).
Eigen::Matrix<double, 6, 1> osculating_elements(double mu, const OrbitState& s);

}  // namespace kanegen
