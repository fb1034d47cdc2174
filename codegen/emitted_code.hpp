// The one contract between the generator and everything that uses its
// output: the generator (generator.hpp) returns an EmittedModel, a list of
// EmittedFunction; the assembler (assembler.hpp) turns it into
//   - the self-contained model header (templates/model.hpp.in),
//   - the C entry file that wraps every function for the runtime's table
//     (engine/generated_api.h), compiled whole (AOT) or one function per
//     translation unit (JIT),
//   - a small JSON manifest (functions, operation counts, namespace, model
//     and generator hashes) that the JIT and kanegen_add_model() read.
// Adding an output function means adding one EmittedFunction: its argument
// list (from the fixed vocabulary below) defines both the C++ signature in
// the header and its C wrapper in the entry file.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "codegen/printer.hpp"

namespace kanegen::codegen {

/// An argument of an emitted function. The C wrapper takes them from
/// KanegenArgs (engine/generated_api.h) by these names; `out` is the
/// function's output array.
enum class Arg {
  t,        ///< const double t: time (only for models with prescribed motion)
  q,        ///< const T* q
  u,        ///< const T* u
  tau,      ///< const T* tau: generalized inputs
  udot_in,  ///< const T* udot_in: accelerations (reactions)
  inputs,   ///< const T* inputs: the named inputs w (only for models that declare some)
  params,   ///< const double* prm: the runtime parameters (only for models that declare some)
  out,      ///< T* <out_name>: the result
};

struct EmittedFunction {
  std::string name;             ///< C++ and table name, e.g. "udot"
  std::string title;            ///< one-line section comment
  std::vector<Arg> args;        ///< in order; exactly one Arg::out
  std::string out_name;         ///< name of the output array, e.g. "M"
  int out_size = 0;             ///< number of doubles written to out
  bool returns_status = false;  ///< int: 0 or the 1-based speed of a non-positive pivot; else void
  bool templated = true;        ///< template <class T> (false: double only, e.g. jacobian)
  bool joint_sincos = false;    ///< computes joint angles' sin and cos in a batch (templates/joint_sincos.inc)
  std::string body;             ///< C++ statements (indented)
  /// Large functions: bodies of the helper functions NAME_part0, NAME_part1,
  /// ... that `body` runs first (same parameters plus the workspace T* w of
  /// `workspace` entries); empty for a function emitted in one piece.
  std::vector<std::string> parts;
  /// Compact functions (outlined_code.hpp): bodies of the kernels NAME_kernel0, ... (T* w, const int* x,
  /// const double* c) that `body` calls `kernel_calls` times, with the workspace T w[workspace] it declares.
  std::vector<std::string> kernels;
  int kernel_calls = 0;
  std::string kernel_tables;  ///< the calls' tables (namespace scope, before the function)
  OpCount kernel_ops;  ///< the kernels' own code (each once); `ops` counts every call's
  int workspace = 0;
  int workspace_values = 0;  ///< compact code: the values kept in its workspace (outlined_code.hpp)
  OpCount ops;
  std::vector<std::pair<std::string, long>> ops_by_pass;  ///< u-dot: its operations by pass (Program::ops_by_pass)
  std::string note;             ///< extra comment lines for the header section (may be empty)
};

struct EmittedModel {
  std::string model_name;       ///< the user's name (in strings)
  std::string identifier;       ///< the C++-safe name (namespace kanegen_gen::<identifier>)
  std::string description;
  std::string model_hash;
  std::string generator_hash;
  int nq = 0, nu = 0, nbodies = 0;
  int nw = 0, ny = 0;           ///< named inputs and outputs (docs/gnc.md)
  int np = 0;                   ///< runtime parameters (docs/sweeps.md)
  std::vector<std::string> parameter_names, parameter_units;
  std::vector<double> parameter_nominal;
  std::vector<std::string> q_names, u_names, input_names, output_names;
  std::string constants;        ///< namespace-scope constant declarations, grouped by body
  std::string support_code;     ///< helper functions the bodies call (e.g. prescribed motion), or empty
  bool orbit_frame_rules = false;  ///< the header needs templates/orbit_frame.inc after support_code
  std::string udot_form;        ///< "composite" or "articulated"
  OpCount udot_composite_ops, udot_articulated_ops;
  std::vector<EmittedFunction> functions;
  const EmittedFunction* find(const std::string& name) const;
};

/// A model name as a C++ identifier: [a-z0-9_] kept, a leading digit or a
/// C++ keyword prefixed by "m_" (the user's name stays in strings).
std::string cpp_identifier(const std::string& name);

}  // namespace kanegen::codegen
