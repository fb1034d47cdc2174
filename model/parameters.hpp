// Runtime parameters (docs/sweeps.md): model values that the generated code
// keeps as inputs instead of folding them into constants, so that a
// dispersed run changes them without a new compile. A model names them under
// `parameters:` (or a sweep file does, for the parameters it disperses); each
// name expands to scalar entries:
//   <body>.mass [kg]          <body>.com -> .com.x .y .z [m]
//   <body>.inertia -> .inertia.xx .yy .zz .xy .xz .yz [kg m^2] (about the com, body axes;
//                             the rigid part of a flexible body)
//   <body>.stiffness [N m/rad or N/m]  <body>.damping [N m s/rad or N s/m]  <body>.rest [rad or m]
//   <body>.frequency -> .frequency1 ... [Hz]   <body>.damping_ratio -> .damping_ratio1 ... (modal)
//   gravity -> gravity.x .y .z [m/s^2]
//   <body>.position -> .position.x .y .z [m]   (the joint frame's origin in the parent frame)
//   <body>.misalignment -> .misalignment.x .y .z [rad]: the joint frame turned by
//                             Rz(z) Ry(y) Rx(x) after its nominal rotation (nominal 0)
// Both engines take the same values: the generic engine evaluates the model
// with them written in (apply_parameters), the generated code reads them
// from its parameter array.
#pragma once

#include <string>
#include <vector>

#include "model/model.hpp"

namespace kanegen {

/// The scalar parameters a name stands for (see the header comment); throws
/// std::invalid_argument naming what is wrong (unknown body, no such joint
/// spring on a fixed joint, no modes, ...).
std::vector<RuntimeParameter> expand_parameter(const Model& model, const std::string& name);

/// The parameter's current value in `model`.
double parameter_value(const Model& model, const RuntimeParameter& p);

/// Writes `values` (one per parameter) into `model` and refreshes what
/// depends on them (mass integrals, modal stiffness and damping). Throws
/// std::invalid_argument for a value outside its domain (a negative mass, a
/// non-positive frequency, an inertia that is not positive semi-definite, ...).
void apply_parameters(Model& model, const std::vector<RuntimeParameter>& params, const VecX& values);

/// The values the JIT keeps as inputs of the generated code although the model
/// does not declare them (so that editing one in the model file reuses the
/// cached library): every non-zero joint stiffness, damping and rest and modal
/// damping ratio not already a declared parameter. They enter the forcing
/// linearly: keeping them symbolic costs a multiply each, where a folded zero
/// would cost nothing (zeros stay folded: making one non-zero recompiles).
/// Nominal values: the model's.
std::vector<RuntimeParameter> implicit_parameters(const Model& model);
/// The model with `extra` appended to its runtime parameters.
Model with_parameters(const Model& model, const std::vector<RuntimeParameter>& extra);
/// with_parameters(model, implicit_parameters(model)).
Model with_implicit_parameters(const Model& model);

/// The model's runtime parameter of this kind, body and index, or -1.
int find_parameter(const std::vector<RuntimeParameter>& params, ParameterKind kind, int body, int index);
/// The index of `p` among the model's runtime parameters, appending it when the model does not have it yet.
int ensure_parameter(Model& model, const RuntimeParameter& p);

}  // namespace kanegen
