// Continuous-time linear models about a state: x_dot ~ f(x0) + A dx + B dw,
// y ~ y0 + C dx + D dw, from the exact derivatives of the generated code
// (dual numbers: Engine::jacobian, input_jacobian, output_jacobian), or from
// central differences for an engine without them (the generic engine).
//
// The state is taken in the tangent space of each free joint's attitude: its
// quaternion's 4 components are replaced by a small rotation dtheta in body
// axes, q = q0 (x) [1; dtheta/2], so the linear model has 2 nu states
// (nq - n_free + nu) and no constraint direction. Attitude outputs likewise
// become small rotations of the output frame (3 rows instead of 4).
// docs/gnc.md states the conventions.
#pragma once

#include <complex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/engine.hpp"
#include "model/state_io.hpp"

namespace kanegen {

struct LinearizeOptions {
  /// Inputs of the model, by name: entries of the named inputs w ("thr",
  /// "mtq.x"), or generalized forces "tau.<speed name>". Empty: every named
  /// input, or every tau when the model declares none.
  std::vector<std::string> inputs;
  /// Outputs, by name: a sensor ("gyro", all its entries) or one entry
  /// ("gyro.x"). Empty: every named output, or the state itself (C = I) when
  /// the model declares none.
  std::vector<std::string> outputs;
  bool finite_differences = false;  ///< central differences even where exact derivatives exist
  /// Leave the ignorable coordinates out of the linear model (LinearModel::ignorable): exact for the
  /// other states, which do not depend on them.
  bool drop_ignorable = false;
  /// "inertial" (default): the state as the model has it. "lvlh": the free root body's coordinates and
  /// speeds relative to the orbit frame (sim/orbit_relative_state.hpp; needs a central field), the
  /// chart in which an LVLH-pointing spacecraft on a circular orbit is an equilibrium.
  std::string frame = "inertial";
};

struct LinearModel {
  std::vector<std::string> state_names;   ///< "q.<coordinate>" (attitude: "q.<body>.rx" ...), "u.<speed>"
  std::vector<std::string> input_names;
  std::vector<std::string> output_names;  ///< attitude outputs: "<sensor>.rx", ".ry", ".rz"
  MatX A, B, C, D;
  VecX x0_dot;        ///< the tangent state's derivative at the point, f(x0)
  VecX y0;            ///< the outputs at the point (tangent rows: attitude rows are 0)
  bool equilibrium = false;
  double residual = 0;  ///< max |f(x0)| / residual_scale
  /// Per state, the scale its x0_dot is judged against for the equilibrium: 1, or in the orbit frame the
  /// orbit's speed n r0 (rows q.<root>.lvlh.x, y, z) and acceleration n^2 r0 (u.<root>.lvlh.vx, vy, vz),
  /// at least 1, so that the orbit's own digits (7e3 m/s carried round) do not read as a residual.
  VecX residual_scale;
  std::string frame = "inertial";  ///< LinearizeOptions::frame
  /// The kinetic-energy metric on the states: T of a perturbation dx of the speeds
  /// is 1/2 dx^T kinetic dx (M on the speed rows; in the orbit frame M carried to the relative speeds at fixed
  /// coordinates: the kinetic energy of the motion relative to the orbit frame). linear_modes() names a mode's
  /// dominant states by their share of its kinetic energy, so that metres, radians and modal coordinates are
  /// compared in one unit (J).
  MatX kinetic;
  std::string method;   ///< how the derivatives were obtained
  /// Coordinates (tangent states "q.<...>") no other state depends on: A's column of each is zero
  /// outside the rows of ignorable coordinates of the same joint (a balanced wheel's angle; a free
  /// body's position without gravity, and its attitude without gravity or external forces).
  std::vector<std::string> ignorable;
  /// Not an equilibrium, but x_dot is zero outside the ignorable coordinates' rows (a wheel spinning
  /// steadily, a body in steady spin): a relative equilibrium, a valid operating point.
  bool relative_equilibrium = false;
  double relative_residual = 0;  ///< max |f(x0)| over the rows of the other states
  bool ignorable_dropped = false;
  /// With drop_ignorable: the ignorable states an output depends on (kept, so that C stays exact).
  std::vector<std::string> ignorable_kept_for_outputs;
};

/// Throws InputError (naming `option`) for unknown input or output names;
/// SingularMassMatrix at a singular point.
LinearModel linearize(Engine& engine, const State& state, const LinearizeOptions& options);

/// One eigenvalue of A (conjugate pairs listed once, Im >= 0).
struct LinearMode {
  std::complex<double> eigenvalue;
  double natural_frequency_hz = 0;  ///< |lambda| / 2 pi
  double damped_frequency_hz = 0;   ///< Im(lambda) / 2 pi
  double damping_ratio = 0;         ///< -Re(lambda) / |lambda| (NaN for a zero eigenvalue)
  /// |lambda| below the eigenvalue noise of a zero eigenvalue (1e-6 sqrt(max(1, |A|_max))): a rigid-body
  /// or ignorable mode (a free body's drift, a wheel's angle), reported as 0 with its states.
  bool zero = false;
  /// Largest share of the mode's kinetic energy first (LinearModel::kinetic: Re(conj(v_i) (K v)_i)); for a
  /// mode without kinetic energy (a zero mode of the coordinates alone) the largest |v_i| of the coordinates.
  std::vector<std::string> dominant_states;
};
/// |eigenvalue| at or below which linear_modes() reports a mode as zero: 1e-6 sqrt(max(1, max|A|)).
double zero_mode_tolerance(const LinearModel& lin);

std::vector<LinearMode> linear_modes(const LinearModel& lin);

nlohmann::ordered_json to_json(const LinearModel& lin, const std::vector<LinearMode>& modes);

/// Small rotation of a unit quaternion's perturbation: dtheta = 2 Xi(q)^T dq,
/// with q (x) [0; v] = Xi(q) v (4 x 3).
Eigen::Matrix<double, 4, 3> quaternion_xi(const Eigen::Vector4d& q);

}  // namespace kanegen
