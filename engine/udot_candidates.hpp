// The u-dot candidates the JIT builds beside a model's library, races
// against the library's own u-dot at the initial state (udot_race.hpp) and
// serves when measured faster (docs/decisions.md, "u-dot candidates"):
//   - u-dot by a second compiler (clang++ where installed), for u-dot of
//     500 operations and more, straight-line or compact: GCC and clang
//     differ most on straight-line code (clang packs pairs of like
//     operations into SSE2 instructions: without it, its tree_15 ran 1.6x
//     slower), and which is faster varies by model (bus_4's by clang++ 1.2x
//     faster, gravity_gradient_boom's 1.5x slower; on compact code chain_8's
//     5 % faster, chain_16's 4 % slower);
//   - u-dot as the other code, by each compiler, in the main code's form:
//     compact code (kernels shared by bodies of one shape,
//     codegen/outlined_code.hpp) where the generator's cost model chose
//     straight-line code, straight-line code where it chose compact code of
//     at most 6,000 operations (near the cost model's threshold the
//     instruction set decides: AVX2 straight-line code can be the faster).
// Each is a library of u-dot alone, <stem>-<key>.udot-<tag>.so, with a cache
// record that keeps the race's outcome; a later load serves what it says.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "engine/generated_engine.hpp"
#include "engine/jit.hpp"
#include "engine/manifest.hpp"

namespace kanegen {

struct UdotCandidate {
  /// what it is, for reports and its record: the second compiler, "compact", "compact by " the second
  /// compiler, "straight-line" or "straight-line by " the second compiler
  std::string name;
  /// its file: <stem>-<key>.udot-<tag>.so ("second", or "second-v3" when built for AVX2; "compact";
  /// "compact-second", or "compact-second-v3"; "straight"; "straight-second", or "straight-second-v3")
  std::string tag;
  std::string udot_form;           ///< its u-dot form (the main library's, or the other code's: the same)
  std::vector<std::string> argv;   ///< one command that compiles and links it
  std::filesystem::path out;       ///< where that command writes it
};

/// The second compiler u-dot is built with, or empty: $KANEGEN_SECOND_CXX ("none": none), else clang++
/// when it is on the PATH; only for optimized builds at the default flags by a main compiler not clang.
std::string second_compiler(const JitOptions& o);

/// The code the JIT should also generate u-dot in, to race it: "compact" when the library's u-dot is one
/// straight-line function of at least 2,000 operations, "straight-line" when it is compact code of 2,000 to
/// 6,000; empty: none (or not an optimized build at the default flags).
std::string other_udot_code(const Manifest& manifest, const JitOptions& o);

/// The candidates of a library of `manifest` built from `entry`, in the temporary directory `tmp`;
/// `other_entry`: the entry file of the sources with u-dot in other_udot_code() (empty: none), of u-dot form
/// `other_form`.
std::vector<UdotCandidate> plan_udot_candidates(const Manifest& manifest, const JitOptions& o,
                                                const std::filesystem::path& tmp, const std::filesystem::path& entry,
                                                const std::filesystem::path& other_entry,
                                                const std::string& other_form);

/// Removes every candidate of the library `so_path` (before a new library is published there).
void remove_udot_candidates(const std::string& so_path);

/// Where the candidate `tag` of the library `so_path` is kept (its record beside it).
std::string udot_candidate_path(const std::string& so_path, const std::string& tag);

/// Serves `e`'s u-dot from the fastest candidate beside `so_path` (built beside the library of checksum
/// `main_checksum`) measured faster than its own: raced now when `fresh` (just built; the outcome goes into
/// the records, and is said on stderr when `talk`), else as the records say.
void attach_udot_candidates(GeneratedEngine& e, const Model& model, const std::string& so_path,
                            const std::string& main_checksum, const JitOptions& o, bool fresh, bool talk);

}  // namespace kanegen
