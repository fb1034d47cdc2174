// Compact emission of a large function (issue 38): its straight-line code
// as calls of small kernels shared by the bodies whose code has the same
// shape. A function of 40-400 KB of straight-line code runs from L2 at
// ~0.24 ns per operation; the same operations as a few kernels of a few KB
// each, called once per body, stay in the 32 KB instruction cache.
//
// The unit is the program's sections (Program::section): each body's code
// of one pass ("body link3: outward pass (velocities)"). A body's later
// sections are fused into its earlier group when everything they read is
// computed by then (outward velocities, mass and velocity terms and bias
// force become one group per body; the inward pass and the outward
// accelerations stay apart, as the recursion orders them).
//
// A group becomes a kernel
//   template <class T> void NAME_kernelK(T* w, const int* x, const double* c)
// whose locals are the group's temporaries (a0, a1, ... in order), whose
// inputs are other groups' temporaries and the state and inputs (copied into
// the workspace first), and whose model constants are c[i], from a table at
// each call (namespace-scope constexpr arrays, internal linkage).
//
// The workspace holds one region per body, all of one stride (unless that
// leaves more than a third of it gaps: then regions of their own lengths, or
// packed). A call gets its region's start as w. A value that every call of a
// kernel finds at the same offset from it is addressed by that constant (a
// chain's like links keep like values at like offsets: classes of values
// joined through the kernels that read them), the rest through the call's
// table x (w[x[i]]).
//
// Each group's text is
// canonical: its externals are numbered in a traversal that orders operands
// by their shape (numbers, locals, an input by its role: which of its
// group's values it is, or a constant by its role: Constants::role), never
// by name, so a chain's middle links print the same text and share a kernel.
// Groups share a kernel only when their texts are equal byte for byte, and
// each call passes the tables of its own group: the values are those of the
// straight-line code, each body's by its own constants (the operations are
// the same; the order of commutative operands may differ, so results agree
// to rounding).
#pragma once

#include <set>
#include <string>
#include <vector>

#include "codegen/constants.hpp"
#include "codegen/printer.hpp"
#include "codegen/program.hpp"

namespace kanegen::codegen {

struct OutlinedBody {
  std::vector<std::string> kernels;  ///< kernel bodies (indented), NAME_kernel0, NAME_kernel1, ...
  std::string tables;                ///< namespace-scope tables of the calls: NAME_x<k> (and NAME_c<k>)
  std::string main;                  ///< the function's body: workspace copies, the calls, the outputs
  int workspace = 0;                 ///< entries of T w[]
  int workspace_values = 0;          ///< the values kept in it (the rest: gaps that align like bodies' regions)
  int calls = 0;                     ///< kernel calls (groups)
  OpCount kernel_ops;                ///< the operations of the kernels' code (each kernel once)
};

/// The listing of `program` as kernels of function `name`; `constants`: the model constants (namespace-scope
/// constexpr doubles). `ops` gets the operations executed (every call's).
OutlinedBody outline(const Program& program, const std::string& name, const Constants& constants,
                     const std::string& indent, OpCount& ops);

}  // namespace kanegen::codegen
